"""What the evaluation protocol reads from each step, per env, before any reset."""

from __future__ import annotations

import numpy as np

from lca.task.state import RobotState


def step_metrics(
    state: RobotState,
    command: np.ndarray,
    terminated: np.ndarray,
    time_out: np.ndarray,
    strike_threshold: float,
) -> dict[str, np.ndarray]:
    """Tracking error = |planar command - planar base velocity| in the base (yaw) frame, the
    frame both are expressed in (m/s); a lateral impact = any foot's horizontal contact force
    above `strike_threshold` (N, the paper's 100 N)."""
    error = command[:, :2] - state.base_lin_vel[:, :2]
    return {
        "terminated": terminated.copy(),
        "time_out": time_out.copy(),
        "lateral_impact": (state.foot_lateral_force > strike_threshold).any(axis=1),
        "track_error": np.linalg.norm(error, axis=1),
        "command_speed": np.linalg.norm(command[:, :2], axis=1),
        "base_pos": state.base_pos.copy(),
        "base_vel": state.base_lin_vel[:, :2].copy(),  # m/s, base frame
        "yaw_rate": state.base_ang_vel[:, 2].copy(),  # rad/s
    }
