"""Episode ends: a fall (base too low or tilted too far) or a non-finite physics state."""

from __future__ import annotations

import numpy as np

from lca.task.config import TerminationConfig
from lca.task.state import RobotState


def fell(state: RobotState, cfg: TerminationConfig) -> np.ndarray:
    # projected gravity z = -cos(tilt)
    tilted = -state.projected_gravity[:, 2] < np.cos(cfg.max_tilt)
    return (state.base_height < cfg.min_base_height) | tilted


def non_finite(state: RobotState, max_joint_vel: float) -> np.ndarray:
    bad = np.zeros(len(state.base_pos), dtype=bool)
    for value in vars(state).values():
        bad |= ~np.isfinite(value.reshape(len(bad), -1)).all(axis=1)
    return bad | (np.abs(np.nan_to_num(state.joint_vel, nan=0.0)) > max_joint_vel).any(axis=1)


TERMINATIONS = ("fall", "time_out", "non_finite")
