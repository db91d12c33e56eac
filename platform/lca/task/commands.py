"""Planar velocity commands and the gait phase clock."""

from __future__ import annotations

import numpy as np

from lca.arrays import Array, namespace
from lca.task.config import CommandConfig


class VelocityCommand:
    """u = (u_x, u_y, u_yaw) per env, resampled every `resample_time_s`; a configured share
    of commands is exactly zero (standing)."""

    def __init__(self, cfg: CommandConfig, num_envs: int, dt: float, rng: np.random.Generator):
        self.cfg = cfg
        self.dt = dt
        self.rng = rng
        self.value = np.zeros((num_envs, 3))
        self.time_left = np.zeros(num_envs)
        self.min_speed = 0.0  # the command curriculum's floor on |u_xy| (0: off)
        self.ranges: dict = {}  # the command curriculum's ranges, in place of the config's

    @property
    def standing(self) -> np.ndarray:
        return np.linalg.norm(self.value, axis=1) < self.cfg.standing_epsilon

    def resample(self, ids: np.ndarray) -> None:
        n = len(ids)
        if n == 0:
            return
        c = self.ranges
        value = np.stack(
            [
                self.rng.uniform(*c.get("lin_vel_x", self.cfg.lin_vel_x), n),
                self.rng.uniform(*c.get("lin_vel_y", self.cfg.lin_vel_y), n),
                self.rng.uniform(*c.get("ang_vel_z", self.cfg.ang_vel_z), n),
            ],
            axis=1,
        )
        if self.min_speed > 0:
            value[:, :2] = _at_least(value[:, :2], self.min_speed)
        value[self.rng.random(n) < c.get("standing_fraction", self.cfg.standing_fraction)] = 0.0
        self.value[ids] = value
        self.time_left[ids] = self.cfg.resample_time_s

    def update(self) -> None:
        self.time_left -= self.dt
        self.resample(np.flatnonzero(self.time_left <= 0))


def _at_least(planar: np.ndarray, floor: float) -> np.ndarray:
    """Planar commands slower than `floor` scaled up to it, direction kept (+x if none)."""
    speed = np.linalg.norm(planar, axis=1, keepdims=True)
    direction = np.where(speed > 0, planar / np.maximum(speed, 1e-12), [1.0, 0.0])
    return np.where(speed < floor, direction * floor, planar)


def gait_phase(episode_time: Array, period: float) -> Array:
    """(N, 2) phase in [0, 1) of the left and right foot, half a period apart."""
    xp = namespace(episode_time)
    phi = xp.remainder(episode_time / period, 1.0)
    return xp.stack([phi, xp.remainder(phi + 0.5, 1.0)], axis=1)
