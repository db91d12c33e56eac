"""`sim.backend=warp`: MuJoCo-Warp on warp's CPU device steps the scene as mjbatch does, within
float32's reach, and the task computed on its arrays matches the task on mjbatch's.

Tolerances: base position 5 mm, joint angles 0.05 rad (99 % of them 0.02) over 50 policy steps
of the same targets on the mixed terrain (measured: 2.2 mm; 0.035 rad at an ankle in contact,
where warp makes one contact for a capsule on a heightfield and MuJoCo C several); every observation
group within 0.25 (scaled units: a joint velocity of 5 rad/s reads 0.25) and every reward
term within 0.02 per step over 20 policy steps of the same actions. Warp computes in float32
and solves contacts with its own kernels, so the two drift apart slowly: they are not equal.
"""

from __future__ import annotations

import os

import numpy as np
import pandas as pd
import pytest
import torch
from omegaconf import OmegaConf

pytest.importorskip("mujoco_warp", reason="the gpu extra: pip install -e '.[gpu]'")
import warp as wp  # noqa: E402
from _cli import SMOKE, run_cli  # noqa: E402

from lca.arrays import to_numpy  # noqa: E402
from lca.config import compose  # noqa: E402
from lca.config.errors import ConfigValueError  # noqa: E402
from lca.sim.batch import BatchedSim  # noqa: E402
from lca.sim.scene import Scene  # noqa: E402
from lca.sim.warp_batch import WarpSim, buffer_sizes  # noqa: E402
from lca.task.env import LocomotionEnv  # noqa: E402
from lca.task.env_state import env_state, restore_env_state  # noqa: E402

# warp's CPU device in CI; .ci/gpu_check runs the same tests with LCA_WARP_DEVICE=cuda
DEVICE = os.environ.get("LCA_WARP_DEVICE", "cpu")
WORLDS = 4
ENV = ["scale=smoke", "task.num_envs=4", "task.observations.noise=false", "sim.num_threads=1"]
WARP = ["sim.backend=warp", f"sim.warp_device={DEVICE}"]


def drive(sim, scene: Scene, steps: int) -> np.ndarray:
    """qpos after each of `steps` policy steps of the same smooth targets around home."""
    sim.reset()
    out = []
    for k in range(steps):
        sim.ctrl[:] = scene.home_joint_pos + 0.1 * np.sin(0.3 * k + np.arange(29))
        for _ in range(4):
            sim.step()
        out.append(np.array(sim.qpos, dtype=np.float64))
    return np.stack(out)


def test_warp_steps_the_scene_as_mjbatch_does(mixed_scene: Scene) -> None:
    c = drive(BatchedSim(mixed_scene, WORLDS, num_threads=1), mixed_scene, 50)
    w = drive(WarpSim(mixed_scene, WORLDS, DEVICE), mixed_scene, 50)
    assert np.abs(c[-1, :, 2] - c[0, :, 2]).max() > 0.01  # the robots moved
    np.testing.assert_allclose(w[:, :, :3], c[:, :, :3], atol=5e-3)
    joints = np.abs(w[:, :, 7:] - c[:, :, 7:])
    assert joints.max() < 0.05 and np.quantile(joints, 0.99) < 0.02


def test_task_on_warp_matches_the_task_on_mjbatch(mixed_cfg) -> None:
    # the same start and commands: the task's random streams differ (NumPy's generator on
    # mjbatch, torch's on warp's device), so nothing random is drawn here
    terrain = [
        "terrain=mixed",
        *(f"task.reset.{k}=0" for k in ("joint_pos_noise", "base_xy_noise", "yaw_range")),
        "task.commands.lin_vel_x=[0.4,0.4]",
        "task.commands.lin_vel_y=[0.1,0.1]",
        "task.commands.ang_vel_z=[0.2,0.2]",
        "task.commands.standing_fraction=0",
    ]
    plain = LocomotionEnv(compose(ENV + terrain))
    warp = LocomotionEnv(compose(ENV + terrain + WARP))
    obs_c, obs_w = plain.reset_all(), warp.reset_all()
    # the task runs on the physics' tensors, on warp's device: no host copy of the state
    device = torch.device(warp.sim.device)  # "cpu" or "cuda:0"
    for value in (warp.sim.qpos, warp.state.base_pos, warp.commands.value, warp.action):
        assert isinstance(value, torch.Tensor) and value.device == device
    assert warp.sim.qpos.data_ptr() == wp.to_torch(warp.sim.d.qpos).data_ptr()  # zero copy
    generator = torch.Generator().manual_seed(0)
    for _ in range(20):
        for group in obs_c.keys():  # noqa: SIM118 (a TensorDict)
            torch.testing.assert_close(obs_w[group].cpu(), obs_c[group], atol=0.25, rtol=0)
        before = {k: v.copy() for k, v in plain.reward_manager.episode_sums.items()}
        before_w = {k: to_numpy(v).copy() for k, v in warp.reward_manager.episode_sums.items()}
        action = 0.3 * torch.randn(WORLDS, plain.num_actions, generator=generator)
        obs_c, _, done_c, _ = plain.step(action)
        obs_w, _, done_w, _ = warp.step(action)
        assert not done_c.any() and not done_w.any()
        for name, sums in plain.reward_manager.episode_sums.items():
            np.testing.assert_allclose(
                to_numpy(warp.reward_manager.episode_sums[name]) - before_w[name],
                sums - before[name],
                atol=0.02,
                err_msg=name,
            )
    assert int(warp.sim.overflows.sum()) == 0  # the buffers sized from the scene held


def test_task_state_round_trip_on_warp() -> None:
    """A checkpoint's env state (tensors and a torch generator on warp's device) puts the
    task back exactly: the same observations and rewards after it, resets included."""
    env = LocomotionEnv(compose([*ENV, *WARP, "task.observations.noise=true"]))
    env.reset_all()
    generator = torch.Generator().manual_seed(1)
    actions = [torch.randn(WORLDS, env.num_actions, generator=generator) for _ in range(10)]
    for action in actions[:4]:
        env.step(action)
    env.reset_all()  # resets draw from the sim's and the task's generators too
    saved = env_state(env)

    def run() -> list[torch.Tensor]:
        out = []
        for action in actions[4:]:
            obs, reward, _, _ = env.step(action)
            out += [obs["policy"].clone(), reward.clone()]
        return out

    first = run()
    restore_env_state(env, saved)
    exact = DEVICE == "cpu"  # a GPU's contact kernels sum in no fixed order
    for a, b in zip(run(), first, strict=True):
        torch.testing.assert_close(a, b, rtol=0, atol=0 if exact else 1e-3)


def test_state_round_trip_is_exact(flat_scene: Scene) -> None:
    sim = WarpSim(flat_scene, 2, DEVICE)
    sim.reset()
    sim.step(8)
    saved = sim.get_state()
    sim.step(8)
    after = np.array(sim.qpos)
    sim.set_state(saved)
    sim.step(8)
    np.testing.assert_array_equal(sim.qpos, after)


def test_buffer_overflows_are_counted_not_printed(flat_scene: Scene, capfd) -> None:
    sim = WarpSim(flat_scene, 2, DEVICE, nconmax=1, njmax=4)
    sim.reset()
    sim.step(20)
    assert (sim.overflows > 0).all()
    assert "overflow" not in capfd.readouterr().out
    assert buffer_sizes(flat_scene.model)[0] >= 8


@pytest.mark.slow
@pytest.mark.e2e
def test_train_evaluate_report_on_warp(tmp_path) -> None:
    run = tmp_path / "warp_run"
    done = run_cli(*SMOKE, *WARP, "hydra.run.dir=" + str(run), cwd=tmp_path, timeout=600)
    assert done.returncode == 0, done.stderr[-3000:]
    assert OmegaConf.load(run / "config.yaml").sim.backend == "warp"
    assert (run / "COMPLETE").exists() and (run / "results.parquet").exists()
    table = pd.read_csv(run / "report" / "sim_table.csv")
    assert set(table["terrain"]) == {c.terrain for c in compose(SMOKE).eval.cells}
    assert (table["n_units"] == compose(SMOKE).eval.units).all()


def test_warp_without_the_extra_fails_at_composition(monkeypatch) -> None:
    import importlib.util

    real = importlib.util.find_spec
    monkeypatch.setattr(
        importlib.util,
        "find_spec",
        lambda name, *a: None if name == "mujoco_warp" else real(name, *a),
    )
    with pytest.raises(ConfigValueError, match=r"sim.backend.*pip install -e '\.\[gpu\]'"):
        compose(["sim.backend=warp"])
    with pytest.raises(ConfigValueError, match="allowed"):
        compose(["sim.backend=jax"])


def test_deployment_cameras_need_mjbatch() -> None:
    with pytest.raises(ConfigValueError, match=r"^perception.source: .*sim.backend=mjbatch"):
        compose(["sim.backend=warp", "perception=deployment"])
