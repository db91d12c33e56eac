"""A GRU actor, a slopes tile and a reward term, added from outside the package, run the
whole pipeline and get rows and columns of their own in the report."""

from __future__ import annotations

import os

import numpy as np
import pandas as pd
import pytest
from _cli import SMOKE, cli_env, run_cli

from lca.config import ConfigError, compose
from lca.learn.train_cfg import build_train_cfg
from lca.sim.terrain import generate

from .conftest import PLUGIN

SEARCH = f"hydra.searchpath=[file://{PLUGIN / 'conf'}]"


def test_unregistered_variants_fail_at_composition() -> None:
    for override, key in [
        ("actor.kind=gru", "actor.kind"),
        ("+terrain.mixture.slopes=1.0", "terrain.mixture.slopes"),
        ("+task.rewards.base_yaw_rate_l2=-0.1", "task.rewards.base_yaw_rate_l2"),
    ]:
        with pytest.raises(ConfigError, match=rf"^{key}: unknown .*allowed: \["):
            compose(["scale=smoke", override])


def test_registered_variants_compose_and_build(example_variants) -> None:
    cfg = compose(["scale=smoke", SEARCH, "actor=gru", "terrain=slopes"])
    actor = build_train_cfg(cfg, "x")["actor"]
    assert actor["rnn_type"] == "gru" and actor["class_name"].endswith("PerceptiveRNNModel")
    terrain = generate(cfg.terrain, cfg.difficulty)
    assert {t.kind for t in terrain.tiles} == {"slopes"}
    assert terrain.heights.max() > 0.1  # the cones rise outwards


@pytest.mark.slow
@pytest.mark.e2e
def test_variants_from_outside_run_train_evaluate_report(tmp_path) -> None:
    env = cli_env() | {
        "LCA_PLUGINS": "example_variants",
        "PYTHONPATH": os.pathsep.join([str(PLUGIN), os.environ.get("PYTHONPATH", "")]),
    }
    cells = "eval.cells=[{terrain: slopes, difficulty: medium}, {terrain: flat, difficulty: hard}]"
    run = tmp_path / "gru_run"
    args = [
        *SMOKE,
        SEARCH,
        "actor=gru",
        "encoder=mlp",
        "terrain=slopes",
        cells,
        "hydra.run.dir=" + str(run),
    ]
    args += ["+task.rewards.base_yaw_rate_l2={weight: -0.1, params: {power: 2.0}}"]
    done = run_cli(*args, cwd=tmp_path, timeout=300, env=env)
    assert done.returncode == 0, done.stderr[-3000:]
    assert "declares no export" in done.stdout
    assert not (run / "exported" / "policy.onnx").exists()
    table = pd.read_csv(run / "report" / "sim_table.csv")
    assert set(table["policy"]) == {"Two-Stage GRU"}  # its own row, not pooled into MLP
    assert set(table["terrain"]) == {"slopes", "flat"}
    tex = (run / "report" / "sim_table.tex").read_text()
    assert "Slopes" in tex and "Flat" in tex and "GRU" in tex
    assert (run / "COMPLETE").exists()


def test_a_term_declared_with_params_gets_them(example_variants) -> None:
    from types import SimpleNamespace

    import numpy as np

    from lca.task.rewards import compute_rewards, weights_and_params

    rewards = {"base_yaw_rate_l2": {"weight": -1.0, "params": {"power": 3.0}}}
    weights, params = weights_and_params(rewards)
    assert weights == {"base_yaw_rate_l2": -1.0} and params == {"base_yaw_rate_l2": {"power": 3.0}}
    ctx = SimpleNamespace(
        state=SimpleNamespace(base_ang_vel=np.array([[0.0, 0.0, 2.0]])), command=np.zeros((1, 3))
    )
    total, _ = compute_rewards(ctx, weights, dt=1.0, params=params)
    assert total == pytest.approx([-8.0])  # |2|^3, not the default square


class StepCounter:
    """A stateful reward term: how many steps each env has lived (reset with the env)."""

    def __init__(self) -> None:
        self.count = None
        self.resets: list[np.ndarray] = []

    def __call__(self, c) -> np.ndarray:
        if self.count is None:
            self.count = np.zeros(len(c.command))
        self.count += 1
        return self.count.copy()

    def reset(self, env_ids: np.ndarray) -> None:
        self.resets.append(np.asarray(env_ids).copy())
        if self.count is not None:
            self.count[env_ids] = 0


def test_a_stateful_term_is_reset_with_its_envs() -> None:
    import torch

    from lca.config.registry import REWARD_TERMS
    from lca.task.env import LocomotionEnv

    term = StepCounter()
    REWARD_TERMS.register("steps_alive")(term)
    try:
        env = LocomotionEnv(compose(["scale=smoke", "terrain=flat", "+task.rewards.steps_alive=0"]))
        env.reset_all()
        for _ in range(3):
            env.step(torch.zeros(env.num_envs, env.num_actions))
        assert term.count.tolist() == [3.0] * env.num_envs
        env._reset_envs(np.array([1, 4]))
        assert term.resets[-1].tolist() == [1, 4]
        assert term.count[[0, 1, 4]].tolist() == [3.0, 0.0, 0.0]
    finally:
        REWARD_TERMS.unregister("steps_alive")


def test_a_term_reads_new_state_from_the_live_physics(example_variants) -> None:
    import mujoco
    import torch

    from lca.task.env import LocomotionEnv

    term = "+task.rewards.body_below={weight: -1.0, params: {body: torso_link, height: 5.0}}"
    env = LocomotionEnv(compose(["scale=smoke", "terrain=flat", term]))
    env.reset_all()
    env.step(torch.zeros(env.num_envs, env.num_actions))
    # the torso's height, from a plain MuJoCo forward pass of world 0's state
    data = mujoco.MjData(env.sim.model)
    data.qpos[:] = env.sim.qpos[0]
    mujoco.mj_kinematics(env.sim.model, data)
    torso = data.xpos[env.sim.body_id("torso_link"), 2]
    assert 0.5 < torso < 1.5
    # weight -1: minus the term, once
    got = env.reward_manager.episode_sums["body_below"][0] / env.dt
    assert got == pytest.approx(-(5.0 - torso), abs=0.05)  # xpos: the step's start
    with pytest.raises(KeyError, match="no body 'tail'"):
        env.sim.body_id("tail")
