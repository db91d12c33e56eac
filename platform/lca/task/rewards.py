"""Reward terms of the paper's table "Nominal reward terms", one small function each.

Every function returns the *unweighted* term, (N,) float; the weights live in
`conf/task/locomotion.yaml`. Names match the paper's table. Notation as in the paper's
Rewards section: contact C_i = 1(|F_i| > F*), stance intent s_i = 1(phi_i < tau or |u| < eps).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from lca.config.registry import REWARD_TERMS
from lca.sim.batch import BatchedSim
from lca.task.config import RewardParams
from lca.task.state import RobotState


@dataclass
class RewardContext:
    state: RobotState
    command: np.ndarray  # (N, 3) u_x, u_y (m/s), u_yaw (rad/s)
    standing: np.ndarray  # (N,) bool, |u| < epsilon
    phase: np.ndarray  # (N, 2) gait phase of left and right foot in [0, 1)
    action: np.ndarray  # (N, J)
    last_action: np.ndarray  # (N, J)
    default_joint_pos: np.ndarray  # (J,)
    joint_lower: np.ndarray  # (J,) soft limits
    joint_upper: np.ndarray  # (J,)
    hip_ids: np.ndarray
    arm_ids: np.ndarray
    torso_ids: np.ndarray
    terminated: np.ndarray  # (N,) bool: fell or non-finite (time-outs excluded)
    params: RewardParams
    # the live batched physics: a term that needs a quantity RobotState lacks reads it here
    # (`sim.data("xpos")[:, sim.body_id("torso_link")]`, `sim.sensor(name)`), no edits elsewhere
    sim: BatchedSim | None = None

    @property
    def contact(self) -> np.ndarray:
        return self.state.foot_force > self.params.contact_threshold

    @property
    def stance(self) -> np.ndarray:
        return (self.phase < self.params.stance_fraction) | self.standing[:, None]


def track_lin_vel_xy_exp(c: RewardContext) -> np.ndarray:
    err = np.sum((c.state.base_lin_vel[:, :2] - c.command[:, :2]) ** 2, axis=1)
    return np.exp(-err / c.params.tracking_sigma)


def track_ang_vel_z_exp(c: RewardContext) -> np.ndarray:
    err = (c.command[:, 2] - c.state.base_ang_vel[:, 2]) ** 2
    return np.exp(-err / c.params.tracking_sigma)


def lin_vel_z_l2(c: RewardContext) -> np.ndarray:
    return c.state.base_lin_vel[:, 2] ** 2


def ang_vel_xy_l2(c: RewardContext) -> np.ndarray:
    return np.sum(c.state.base_ang_vel[:, :2] ** 2, axis=1)


def dof_torques_l2(c: RewardContext) -> np.ndarray:
    """The table's formula: sum_j |qdot_j| |tau_j| (mechanical power)."""
    return np.sum(np.abs(c.state.joint_vel) * np.abs(c.state.torque), axis=1)


def dof_acc_l2(c: RewardContext) -> np.ndarray:
    return np.sum(c.state.joint_acc**2, axis=1)


def dof_vel_l2(c: RewardContext) -> np.ndarray:
    return np.sum(c.state.joint_vel**2, axis=1)


def action_rate_l2(c: RewardContext) -> np.ndarray:
    return np.sum((c.action - c.last_action) ** 2, axis=1)


def undesired_contacts(c: RewardContext) -> np.ndarray:
    """Hip, thigh or shin touching anything (> F*), plus feet struck laterally above the
    strike threshold: the section's foot-strike cost counted as events, as the table does."""
    legs = np.sum(c.state.leg_contact_force > c.params.contact_threshold, axis=1)
    strikes = np.sum(c.state.foot_lateral_force > c.params.strike_threshold, axis=1)
    return (legs + strikes).astype(float)


def feet_strike(c: RewardContext) -> np.ndarray:
    """The section's r_strike = sum_i |F_i^xy| in newtons (weight 0 by default)."""
    return np.sum(c.state.foot_lateral_force, axis=1)


def contact_no_vel(c: RewardContext) -> np.ndarray:
    speed2 = np.sum(c.state.foot_vel**2, axis=2)
    return np.sum(speed2 * c.contact, axis=1)


def _deviation(c: RewardContext, ids: np.ndarray) -> np.ndarray:
    return np.sum(np.abs(c.state.joint_pos[:, ids] - c.default_joint_pos[ids]), axis=1)


def joint_deviation_hip(c: RewardContext) -> np.ndarray:
    return _deviation(c, c.hip_ids)


def joint_deviation_arms(c: RewardContext) -> np.ndarray:
    return _deviation(c, c.arm_ids)


def joint_deviation_torso(c: RewardContext) -> np.ndarray:
    return _deviation(c, c.torso_ids)


def height_torso(c: RewardContext) -> np.ndarray:
    return (c.state.base_height - c.params.base_height_target) ** 2


def feet_clearance(c: RewardContext) -> np.ndarray:
    """Minus the section's swing-height cost, so the table's +1.0 weight penalises it:
    -sum_i (1 - C_i) ((z_i - h*) / h_scale)^2 tanh(kappa |v_i^xy|)."""
    p = c.params
    target = np.where(c.standing, p.stand_height, p.swing_height)[:, None]
    err = ((c.state.foot_height - target) / p.clearance_scale) ** 2
    gate = np.tanh(p.clearance_gate * np.linalg.norm(c.state.foot_vel[..., :2], axis=2))
    return -np.sum((1.0 - c.contact) * err * gate, axis=1)


def feet_slide(c: RewardContext) -> np.ndarray:
    speed2 = np.sum(c.state.foot_vel[..., :2] ** 2, axis=2)
    return np.sum(speed2 * c.contact, axis=1)


def phase_contact(c: RewardContext) -> np.ndarray:
    """XNOR of detected contact and stance intent, summed over feet: 2 - sum |c_i - s_i|."""
    return np.sum(c.contact == c.stance, axis=1).astype(float)


def stand_still(c: RewardContext) -> np.ndarray:
    dev = np.sum(np.abs(c.state.joint_pos - c.default_joint_pos), axis=1)
    return dev * c.standing


def feet_flat(c: RewardContext) -> np.ndarray:
    """1 - exp(-k sum_i C_i |pitch_i|): the table's weight -1.0 makes it the section's cost."""
    tilt = np.sum(np.abs(c.state.foot_pitch) * c.contact, axis=1)
    return 1.0 - np.exp(-c.params.flat_feet_k * tilt)


def flat_orientation_l2(c: RewardContext) -> np.ndarray:
    return np.sum(c.state.projected_gravity[:, :2] ** 2, axis=1)


def dof_pos_limits(c: RewardContext) -> np.ndarray:
    q = c.state.joint_pos
    over = np.clip(q - c.joint_upper, 0.0, None) + np.clip(c.joint_lower - q, 0.0, None)
    return np.sum(over, axis=1)


def alive(c: RewardContext) -> np.ndarray:
    return (~c.terminated).astype(float)


def termination_penalty(c: RewardContext) -> np.ndarray:
    return c.terminated.astype(float)


# The table's terms, registered by name (lca.config.registry); a plugin adds its own the
# same way, REWARD_TERMS.register("name")(f), then gives it a weight under task.rewards. A
# term that keeps per-env state is an object with __call__(ctx, **params) and reset(env_ids),
# which the env calls for the envs it resets.
for _term in (
    track_lin_vel_xy_exp,
    track_ang_vel_z_exp,
    lin_vel_z_l2,
    ang_vel_xy_l2,
    dof_torques_l2,
    dof_acc_l2,
    dof_vel_l2,
    action_rate_l2,
    undesired_contacts,
    contact_no_vel,
    joint_deviation_hip,
    joint_deviation_arms,
    joint_deviation_torso,
    height_torso,
    feet_clearance,
    feet_slide,
    phase_contact,
    stand_still,
    feet_flat,
    flat_orientation_l2,
    dof_pos_limits,
    alive,
    termination_penalty,
    feet_strike,
):
    REWARD_TERMS.register(_term.__name__)(_term)


def weights_and_params(rewards) -> tuple[dict[str, float], dict[str, dict]]:
    """`task.rewards` (name -> weight or {weight, params}) as weights and per-term params."""
    weights, params = {}, {}
    for name, entry in rewards.items():
        if isinstance(entry, int | float):
            weights[name] = float(entry)
        else:
            weights[name] = float(entry["weight"])
            params[name] = dict(entry.get("params") or {})
    return weights, params


def compute_rewards(
    ctx: RewardContext,
    weights: dict[str, float],
    dt: float,
    *,
    only_positive: bool = False,
    penalty_scale: float = 1.0,
    scaled_terms: frozenset[str] | None = None,
    unclipped: frozenset[str] = frozenset(),
    params: dict[str, dict] | None = None,
    boosts: dict[str, float] | None = None,
    fns: dict[str, Callable] | None = None,
) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """Total reward and each weighted term, (N,). Terms are per second of simulated time,
    scaled by the policy step `dt`, so weights do not depend on the control rate.

    `penalty_scale` multiplies the negative contributions of `scaled_terms` (None: every
    term) and `boosts` the weights of the terms it names -- the reward curriculum; 1 and {}
    are the paper's table. `fns` are the registered term functions, resolved once by the env
    (looked up here when not given). `only_positive` (legged_gym's
    `only_positive_rewards`) clips the sum of all terms but the termination penalty at zero
    before adding that penalty: while a young policy's penalties outweigh its rewards, living
    longer would otherwise cost more than falling early. The `unclipped` terms are added
    after the clip too, so their gradient reaches the policy whatever the clipped sum."""
    terms = {}
    params, boosts = params or {}, boosts or {}
    fns = fns or {name: REWARD_TERMS[name] for name in weights}
    for name, weight in weights.items():
        value = weight * boosts.get(name, 1.0) * fns[name](ctx, **params.get(name, {})) * dt
        if penalty_scale != 1.0 and (scaled_terms is None or name in scaled_terms):
            value = np.where(value < 0, penalty_scale * value, value)
        terms[name] = value
    after_clip = unclipped | {"termination_penalty"} if only_positive else frozenset()
    total, outside = np.zeros(len(ctx.command)), np.zeros(len(ctx.command))
    for name, value in terms.items():
        if name in after_clip:
            outside = outside + value
        else:
            total = total + value
    if only_positive:
        total = np.clip(total, 0.0, None)
    return total + outside, terms
