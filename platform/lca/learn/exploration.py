"""An exploration schedule: a falling ceiling on the policy's action std.

A wide Gaussian finds stepping (a robot that is shaken must step to stay up); the same noise
makes every gait sloppy and costly once the penalties are the paper's. The ceiling falls
linearly from the initial std (held until `noise_start` x max_iterations) to `final_noise_std`
at `noise_deadline` x max_iterations and stays there; below it the std is rsl-rl's learned
parameter.
"""

from __future__ import annotations

import math
import re

import torch

from lca.learn.config import ActorConfig
from lca.sim.robot import JOINT_GROUPS


def noise_ceiling(
    cfg: ActorConfig, iteration: int, total_iterations: int, penalty_progress: float = 1.0
) -> float | None:
    """The cap on the action std at `iteration`, or None when the std is free.
    `penalty_progress` (0 at the reward curriculum's start, 1 at the paper's weights) drives
    it instead with `noise_by: penalties`; the deadline holds either way."""
    if cfg.final_noise_std <= 0:
        return None
    end = max(math.ceil(cfg.noise_deadline * total_iterations), 1)
    start = min(math.ceil(cfg.noise_start * total_iterations), end - 1)
    progress = min(max(iteration - start, 0) / (end - start), 1.0)
    if cfg.noise_by == "penalties":
        progress = 1.0 if iteration >= end else float(penalty_progress)
    return cfg.init_noise_std + (cfg.final_noise_std - cfg.init_noise_std) * progress


def apply_ceiling(actor, ceiling: float | None) -> None:
    """Clamp the actor's Gaussian std to `ceiling` (rsl-rl clamps to `std_range`)."""
    if ceiling is not None:
        actor.distribution.std_range[1] = float(ceiling)
        actor.distribution.log_std_range[1] = math.log(float(ceiling))


def initial_stds(cfg: ActorConfig, joint_names: list[str]) -> torch.Tensor:
    """(J,) initial action std per joint: the first matching `init_noise_std_joints` key (a
    joint group of `lca.sim.robot.JOINT_GROUPS` or a regex), else `init_noise_std`."""
    stds = []
    for name in joint_names:
        match = next(
            (k for k in cfg.init_noise_std_joints if re.fullmatch(JOINT_GROUPS.get(k, k), name)),
            None,
        )
        stds.append(cfg.init_noise_std_joints[match] if match else cfg.init_noise_std)
    return torch.tensor(stds, dtype=torch.float32)


def set_initial_stds(actor, cfg: ActorConfig, joint_names: list[str]) -> None:
    """Write the per-joint initial stds into a fresh actor's Gaussian (scalar std type)."""
    if not cfg.init_noise_std_joints:
        return
    with torch.no_grad():
        actor.distribution.std_param.copy_(initial_stds(cfg, joint_names))
