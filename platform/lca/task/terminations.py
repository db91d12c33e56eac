"""Episode ends: a fall (base too low or tilted too far) or a non-finite physics state."""

from __future__ import annotations

import math

from lca.arrays import Array, device_of, namespace
from lca.task.config import TerminationConfig
from lca.task.state import RobotState


def fell(state: RobotState, cfg: TerminationConfig) -> Array:
    # projected gravity z = -cos(tilt)
    tilted = -state.projected_gravity[:, 2] < math.cos(cfg.max_tilt)
    return (state.base_height < cfg.min_base_height) | tilted


def non_finite(state: RobotState, max_joint_vel: float) -> Array:
    xp, n = namespace(state.base_pos), state.base_pos.shape[0]
    bad = xp.zeros(n, dtype=xp.bool, device=device_of(state.base_pos))
    for value in vars(state).values():
        bad = bad | ~xp.all(xp.isfinite(xp.reshape(value, (n, -1))), axis=1)
    vel = state.joint_vel
    fast = xp.any(xp.abs(xp.where(xp.isnan(vel), 0.0, vel)) > max_joint_vel, axis=1)
    return bad | fast


TERMINATIONS = ("fall", "time_out", "non_finite")
