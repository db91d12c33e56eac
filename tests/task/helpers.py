"""Hand-built robot states for the task-layer tests."""

from __future__ import annotations

import numpy as np

from lca.task.state import RobotState

J = 29
DEFAULT_Q = np.linspace(-0.3, 0.3, J)  # non-zero so deviations are measured from it


def make_state(n: int = 2, **fields: np.ndarray) -> RobotState:
    """A robot standing still at the nominal height, default pose, feet on the ground."""
    base = {
        "base_pos": np.zeros((n, 3)),
        "base_quat": np.tile([1.0, 0.0, 0.0, 0.0], (n, 1)),
        "base_lin_vel": np.zeros((n, 3)),
        "base_lin_vel_world": np.zeros((n, 3)),
        "base_ang_vel": np.zeros((n, 3)),
        "projected_gravity": np.tile([0.0, 0.0, -1.0], (n, 1)),
        "base_height": np.full(n, 0.77),
        "joint_pos": np.tile(DEFAULT_Q, (n, 1)),
        "joint_vel": np.zeros((n, J)),
        "joint_acc": np.zeros((n, J)),
        "torque": np.zeros((n, J)),
        "foot_pos": np.zeros((n, 2, 3)),
        "foot_vel": np.zeros((n, 2, 3)),
        "foot_pitch": np.zeros((n, 2)),
        "foot_height": np.zeros((n, 2)),
        "foot_force": np.zeros((n, 2)),
        "foot_lateral_force": np.zeros((n, 2)),
        "leg_contact_force": np.zeros((n, 6)),
    }
    unknown = set(fields) - set(base)
    assert not unknown, unknown
    base.update({k: np.asarray(v, dtype=float) for k, v in fields.items()})
    return RobotState(**base)
