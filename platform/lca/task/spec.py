"""A JSON-able description of the composed task: observation groups, rewards, commands."""

from __future__ import annotations

from dataclasses import asdict

import mujoco
from omegaconf import DictConfig, OmegaConf

from lca.sim.robot import build_robot_spec
from lca.task import observations
from lca.task.rewards import weights_and_params
from lca.task.terminations import TERMINATIONS


def _term(term: observations.Term, history: int = 1, noisy: bool = True) -> dict:
    d = asdict(term)
    d.pop("value")  # the function that reads it: not part of the description
    d["dim"] = term.dim * history
    d["scale"] = list(term.scale) if isinstance(term.scale, tuple) else term.scale
    d["noise"] = term.noise if noisy else 0.0
    if history > 1:
        d["history"] = history
    return d


def describe_task(cfg: DictConfig) -> dict:
    task = cfg.task
    spec = build_robot_spec(cfg.robot)
    num_joints = sum(1 for j in spec.joints if j.type == mujoco.mjtJoint.mjJNT_HINGE)
    k = task.observations.history
    weights, params = weights_and_params(task.rewards)
    noisy = bool(task.observations.noise)
    hist = observations.history_terms(task.observations, num_joints)
    current = observations.current_terms(task.observations, num_joints)
    policy_terms = [_term(t, k, noisy) for t in hist] + [_term(t) for t in current]
    critic_terms = [_term(t, k, noisy=False) for t in hist] + [_term(t) for t in current]
    critic_terms.append({"name": "base_lin_vel_world", "dim": 3, "scale": 1.0, "noise": 0.0})
    ar, ac = task.observations.actor_grid
    cr, cc = task.observations.critic_grid
    height_noise = float(cfg.difficulty.height_noise) if noisy else 0.0
    groups = {
        "policy": policy_terms,
        "height": [
            {
                "name": "height_map",
                "dim": ar * ac,
                "scale": 1.0,
                "noise": height_noise,
                "dropout": task.observations.height_dropout,
                "extent_m": [
                    ar * task.observations.actor_spacing - task.observations.actor_spacing,
                    ac * task.observations.actor_spacing - task.observations.actor_spacing,
                ],
                "perception": bool(task.perception),
            }
        ],
        "critic": critic_terms,
        "critic_height": [{"name": "height_map", "dim": cr * cc, "scale": 1.0, "noise": 0.0}],
    }
    shapes = {
        "policy": [sum(t["dim"] for t in policy_terms)],
        "height": [1, ar, ac],
        "critic": [sum(t["dim"] for t in critic_terms)],
        "critic_height": [1, cr, cc],
    }
    described = {g: {"shape": shapes[g], "terms": groups[g]} for g in groups}
    for g in ("policy", "critic"):
        described[g]["layout"] = f"{k} history frames (newest first), then the current terms"
    return {
        "observations": described,
        "actions": {"dim": num_joints, "scale": task.action_scale, "clip": task.action_clip},
        "rewards": weights,
        "reward_term_params": params,
        "only_positive_rewards": bool(task.only_positive_rewards),
        "reward_params": OmegaConf.to_container(task.reward_params),
        "commands": OmegaConf.to_container(task.commands),
        "terminations": list(TERMINATIONS),
        "episode_length_s": task.episode_length_s,
        "policy_dt": cfg.sim.timestep * cfg.sim.decimation,
    }
