"""What the evaluation protocol reads from each step, per env, before any reset."""

from __future__ import annotations

from lca.arrays import Array, namespace
from lca.task.state import RobotState


def step_metrics(
    state: RobotState,
    command: Array,
    terminated: Array,
    time_out: Array,
    strike_threshold: float,
) -> dict[str, Array]:
    """Tracking error = |planar command - planar base velocity| in the base (yaw) frame, the
    frame both are expressed in (m/s); a lateral impact = any foot's horizontal contact force
    above `strike_threshold` (N, the paper's 100 N). Copies: the env resets rows after."""
    xp = namespace(command)
    error = command[:, :2] - state.base_lin_vel[:, :2]

    def copy(value: Array) -> Array:
        return xp.asarray(value, copy=True)

    return {
        "terminated": copy(terminated),
        "time_out": copy(time_out),
        "lateral_impact": xp.any(state.foot_lateral_force > strike_threshold, axis=1),
        "track_error": xp.linalg.vector_norm(error, axis=1),
        "command_speed": xp.linalg.vector_norm(command[:, :2], axis=1),
        "base_pos": copy(state.base_pos),
        "base_vel": copy(state.base_lin_vel[:, :2]),  # m/s, base frame
        "yaw_rate": copy(state.base_ang_vel[:, 2]),  # rad/s
    }
