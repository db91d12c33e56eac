"""Planar velocity commands and the gait phase clock."""

from __future__ import annotations

from typing import Any

import numpy as np

from lca.arrays import Array, draw, like, namespace, zeros
from lca.task.config import CommandConfig


class VelocityCommand:
    """u = (u_x, u_y, u_yaw) per env, resampled every `resample_time_s`; a configured share
    of commands is exactly zero (standing). The buffers are arrays like `reference` (NumPy
    float64 by default; torch tensors on the physics device, with a torch.Generator)."""

    def __init__(
        self,
        cfg: CommandConfig,
        num_envs: int,
        dt: float,
        rng: Any,
        reference: Array | None = None,
    ):
        self.cfg = cfg
        self.dt = dt
        self.rng = rng
        ref = np.zeros(0) if reference is None else reference
        self.xp = namespace(ref)
        self.value = zeros((num_envs, 3), ref)
        self.time_left = zeros(num_envs, ref)
        self.min_speed = 0.0  # the command curriculum's floor on |u_xy| (0: off)
        self.ranges: dict = {}  # the command curriculum's ranges, in place of the config's

    @property
    def standing(self) -> Array:
        return self.xp.linalg.vector_norm(self.value, axis=1) < self.cfg.standing_epsilon

    def resample(self, ids: Array) -> None:
        n = int(ids.shape[0])
        if n == 0:
            return
        c, ref = self.ranges, self.value
        value = self.xp.stack(
            [
                draw(self.rng, *c.get("lin_vel_x", self.cfg.lin_vel_x), n, ref),
                draw(self.rng, *c.get("lin_vel_y", self.cfg.lin_vel_y), n, ref),
                draw(self.rng, *c.get("ang_vel_z", self.cfg.ang_vel_z), n, ref),
            ],
            axis=1,
        )
        if self.min_speed > 0:
            value[:, :2] = _at_least(value[:, :2], self.min_speed)
        standing = c.get("standing_fraction", self.cfg.standing_fraction)
        value[draw(self.rng, 0.0, 1.0, n, ref) < standing] = 0.0
        self.value[ids] = value
        self.time_left[ids] = self.cfg.resample_time_s

    def update(self) -> None:
        self.time_left -= self.dt
        self.resample(self.xp.nonzero(self.time_left <= 0)[0])


def _at_least(planar: Array, floor: float) -> Array:
    """Planar commands slower than `floor` scaled up to it, direction kept (+x if none)."""
    xp = namespace(planar)
    speed = xp.linalg.vector_norm(planar, axis=1, keepdims=True)
    direction = xp.where(speed > 0, planar / xp.clip(speed, min=1e-12), like([1.0, 0.0], planar))
    return xp.where(speed < floor, direction * floor, planar)


def gait_phase(episode_time: Array, period: float) -> Array:
    """(N, 2) phase in [0, 1) of the left and right foot, half a period apart."""
    xp = namespace(episode_time)
    phi = xp.remainder(episode_time / period, 1.0)
    return xp.stack([phi, xp.remainder(phi + 0.5, 1.0)], axis=1)
