"""Everything a `LocomotionEnv` carries from one step to the next, as a picklable dict.

Saved with a training checkpoint, it makes a resumed run continue exactly where the killed
one stopped: MuJoCo's integration state (qpos, qvel, warm start, ...; `mjSTATE_INTEGRATION`,
enough for bit-identical stepping), the per-env model parameters drawn by domain
randomisation, the task's buffers (histories, commands, clocks, actions, episode sums), the
current observations, and the random generators' states.
"""

from __future__ import annotations

import copy

import numpy as np
import torch

from lca.arrays import copy_of, like, rng_state, set_rng_state

ARRAYS = ("_episode_steps", "action", "last_action")
COUNTERS = ("nonfinite_resets", "nonfinite_actions")
SHAPING = ("penalty_scale", "only_positive")  # the reward manager's
LEVEL_TRACKS = ("path", "asked", "lived", "mark")  # TerrainLevels' per-episode distances


def env_state(env) -> dict:
    sim = env.sim
    state = {
        "sim": sim.get_state(),
        "warning": copy_of(env.warnings),
        "friction": None if sim._friction is None else copy_of(sim._friction),
        "body_mass": None if sim._body_mass is None else copy_of(sim._body_mass),
        "history": copy_of(env.history.buffer),
        "critic_history": copy_of(env.critic_history.buffer),
        "commands": {
            "value": copy_of(env.commands.value),
            "time_left": copy_of(env.commands.time_left),
            "min_speed": env.commands.min_speed,
        },
        "episode_sums": {k: copy_of(v) for k, v in env.reward_manager.episode_sums.items()},
        "perception": env.perception,
        "obs": {k: v.clone() for k, v in env._obs.items()},
        "robot_state": copy.deepcopy(vars(env._state)),
        "rng": rng_state(env.rng),
        "sim_rng": rng_state(sim.rng),
        "camera": None,
        "terrain_levels": None,
    }
    state |= {name: copy_of(getattr(env, name)) for name in ARRAYS}
    state |= {name: getattr(env, name) for name in COUNTERS}
    state |= {name: getattr(env.reward_manager, name) for name in SHAPING}
    if env.terrain_levels is not None:
        levels = env.terrain_levels
        state["terrain_levels"] = {
            "level": copy_of(levels.level),
            "origin": copy_of(sim.env_origin),
        } | {name: copy_of(getattr(levels, name)) for name in LEVEL_TRACKS}
    if env.camera_map is not None:
        state["camera"] = {"frame": env.camera_map.frame.copy(), "map": env.camera_map.map.copy()}
    return state


def restore_env_state(env, state: dict) -> None:
    """Put `state` (from `env_state` of an env built from the same config) back."""
    sim = env.sim
    shape = sim.get_state().shape
    if state["sim"].shape != shape:
        raise ValueError(
            f"saved env state is for {state['sim'].shape[0]} envs of state size "
            f"{state['sim'].shape[1]}; this env has {shape}"
        )
    sim.set_state(state["sim"])
    env.warnings[:] = state["warning"]
    if state["friction"] is not None:
        ones = like(np.ones(env.num_envs), env._ref)
        sim.set_friction_scale(env._all_ids(), ones)  # expand
        sim._friction[:] = state["friction"]
    if state["body_mass"] is not None:
        sim._body_mass[:] = state["body_mass"]
        sim.set_const(env._all_ids())
    env.history.buffer[:] = state["history"]
    env.critic_history.buffer[:] = state["critic_history"]
    env.commands.value[:] = state["commands"]["value"]
    env.commands.time_left[:] = state["commands"]["time_left"]
    env.commands.min_speed = state["commands"]["min_speed"]
    for name, sums in state["episode_sums"].items():
        env.reward_manager.episode_sums[name][:] = sums
    for name in ARRAYS:
        getattr(env, name)[:] = state[name]
    for name in COUNTERS:
        setattr(env, name, state[name])
    for name in SHAPING:
        setattr(env.reward_manager, name, state[name])
    if state.get("terrain_levels") is not None:
        env.terrain_levels.level[:] = state["terrain_levels"]["level"]
        sim.env_origin[:] = state["terrain_levels"]["origin"]
        for name in LEVEL_TRACKS:  # states saved before the tracks existed start them at 0
            if name in state["terrain_levels"]:
                getattr(env.terrain_levels, name)[:] = state["terrain_levels"][name]
    env.perception = state["perception"]
    for key, value in state["obs"].items():
        env._obs[key] = value.to(env.device)
    for key, value in state["robot_state"].items():
        setattr(env._state, key, value)
    set_rng_state(env.rng, state["rng"])
    set_rng_state(sim.rng, state["sim_rng"])
    if state["camera"] is not None:
        env.camera_map.frame[:] = state["camera"]["frame"]
        env.camera_map.map[:] = state["camera"]["map"]
    env.episode_length_buf = torch.as_tensor(env._episode_steps, device=env.device)
    sim.forward()  # derived quantities (sensors, contacts) from the restored state
