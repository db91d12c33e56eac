"""The paper's hardware protocol in simulation: per task, N trials from a standing start
with a 0.3 m/s forward command, stopping when the task is completed.

success = the base passes the task's goal line without a fall within the time limit;
drift = |lateral base displacement| at completion; precision = mean drift over the
successful trials. Blind policies run with perception off, the others through the
deployment perception pipeline (depth cameras -> filtered 11 x 11 map). With `eval.videos`
the first trial of each task is also filmed into `clips/hw_<task>.mp4`.
"""

from __future__ import annotations

import copy
import time
from collections.abc import Iterable
from pathlib import Path

import numpy as np
import pandas as pd
import torch
from omegaconf import DictConfig

from lca.arrays import to_numpy
from lca.config import load_option
from lca.evaluate.clips import Setting, gl_missing, save, shoot
from lca.evaluate.policy import final_checkpoint, load_policy, sees_map
from lca.evaluate.protocol import trial_config
from lca.evaluate.rollout import rollout, start
from lca.sim.hardware import HardwareTask, build_task
from lca.store import RunDir, atomic_write
from lca.task.env import LocomotionEnv

HARDWARE_CLIP_S = 12.0  # s at most of a hardware task's clip (eval.videos)


def task_config(cfg: DictConfig) -> DictConfig:
    hw = cfg.hardware
    c = trial_config(cfg, hw.trials, hw.time_limit_s, [hw.command_x, hw.command_x])
    c.task.reset.yaw_range = 0.0  # facing the task
    c.task.reset.base_xy_noise = 0.0
    c.perception = load_option("perception", "deployment")
    return c


@torch.inference_mode()
def run_trials(env: LocomotionEnv, policy, task: HardwareTask, steps: int) -> pd.DataFrame:
    obs = start(env, policy)
    start_y = to_numpy(env.sim.qpos[:, 1]).astype(np.float64)
    return score_trials(rollout(env, policy, obs, steps), start_y, task.goal_x, env.dt)


def score_trials(
    steps: Iterable[tuple[int, dict]], start_y: np.ndarray, goal_x: float, dt: float
) -> pd.DataFrame:
    """Each trial's outcome from its per-step metrics: a success when the base first crosses
    `goal_x` without having fallen or timed out; the signed lateral drift from `start_y` and
    the time at that step."""
    n = len(start_y)
    active = np.ones(n, dtype=bool)
    success = np.zeros(n, dtype=bool)
    drift = np.full(n, np.nan)
    time_s = np.full(n, np.nan)
    for step, m in steps:
        done_now = active & (m["base_pos"][:, 0] >= goal_x) & ~m["terminated"]
        success |= done_now
        # the net lateral drift, signed: the table's precision removes a fixed bias
        drift = np.where(done_now, m["base_pos"][:, 1] - start_y, drift)
        time_s = np.where(done_now, (step + 1) * dt, time_s)
        active &= ~(done_now | m["terminated"] | m["time_out"])
        if not active.any():
            break
    return pd.DataFrame(
        {"trial": np.arange(n), "success": success, "drift_m": drift, "time_s": time_s}
    )


def run_hardware(run_dir: Path, cfg: DictConfig, log=print) -> pd.DataFrame:
    """Every task of `cfg.hardware` on the run's final policy; writes hardware.csv."""
    run_dir = Path(run_dir)
    with RunDir(run_dir).lock():
        return _run_hardware(run_dir, cfg, log)


def _run_hardware(run_dir: Path, cfg: DictConfig, log) -> pd.DataFrame:
    c = task_config(cfg)
    checkpoint = final_checkpoint(run_dir)
    perception = sees_map(checkpoint)
    steps = int(round(c.hardware.time_limit_s / (c.sim.timestep * c.sim.decimation)))
    frames = []
    for name in c.hardware.tasks:
        task, scene = build_task(c, name)
        env = LocomotionEnv(c, scene=scene)
        env.set_perception(perception)
        env.reseed(c.eval.seed)
        policy = load_policy(c, env, checkpoint)
        trials = run_trials(env, policy, task, steps)
        trials.insert(0, "task", name)
        frames.append(trials)
        if log:
            log(f"[lca] hardware {run_dir.name} {name}: {int(trials.success.sum())}/{len(trials)}")
    result = pd.concat(frames, ignore_index=True)
    atomic_write(run_dir / "hardware.csv", result.to_csv(index=False))
    if cfg.eval.videos and not gl_missing(run_dir.name, log):
        for name in c.hardware.tasks:
            t0 = time.perf_counter()
            clip = shoot(hardware_setting(cfg, name, checkpoint), HARDWARE_CLIP_S)
            path = save(clip.frames, clip.fps, run_dir / "clips" / f"hw_{name}.mp4")
            if log:
                log(
                    f"[lca] clip {run_dir.name} {path.name}: {len(clip.frames)} frames "
                    f"in {time.perf_counter() - t0:.1f} s"
                )
    return result


def hardware_setting(cfg: DictConfig, name: str, checkpoint: Path) -> Setting:
    """The first trial of hardware task `name` (the protocol's settings, one trial); its goal
    is the task's goal line."""
    one = copy.deepcopy(cfg)
    one.hardware.trials = 1
    c = task_config(one)
    task, scene = build_task(c, name)
    env = LocomotionEnv(c, scene=scene)
    env.set_perception(sees_map(checkpoint))
    env.reseed(c.eval.seed)
    policy = load_policy(c, env, checkpoint)

    def goal(metrics: dict) -> bool:
        return bool(metrics["base_pos"][0, 0] >= task.goal_x)

    label = f"hardware: {name}"
    return Setting(c, env, policy, label, task.terrain, task.decorate, goal)
