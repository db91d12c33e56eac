"""Reward terms of the paper's table "Nominal reward terms", one small function each.

Every function returns the *unweighted* term, (N,) float; the weights live in
`conf/task/locomotion.yaml`. Terms use the array API of their inputs (`RewardContext.xp`), so
one definition serves NumPy arrays (mjbatch) and torch tensors (lca.arrays). Names match the
paper's table. Notation as in the paper's Rewards section: contact C_i = 1(|F_i| > F*),
stance intent s_i = 1(phi_i < tau or |u| < eps).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import cached_property

from lca.arrays import Array, as_float, device_of, namespace
from lca.config.registry import REWARD_TERMS
from lca.sim.batch import BatchedSim
from lca.task.config import RewardParams
from lca.task.state import RobotState


@dataclass
class RewardContext:
    state: RobotState
    command: Array  # (N, 3) u_x, u_y (m/s), u_yaw (rad/s)
    standing: Array  # (N,) bool, |u| < epsilon
    phase: Array  # (N, 2) gait phase of left and right foot in [0, 1)
    action: Array  # (N, J)
    last_action: Array  # (N, J)
    default_joint_pos: Array  # (J,)
    joint_lower: Array  # (J,) soft limits
    joint_upper: Array  # (J,)
    hip_ids: Array
    arm_ids: Array
    torso_ids: Array
    terminated: Array  # (N,) bool: fell or non-finite (time-outs excluded)
    params: RewardParams
    # the live batched physics: a term that needs a quantity RobotState lacks reads it here
    # (`sim.data("xpos")[:, sim.body_id("torso_link")]`, `sim.sensor(name)`), no edits elsewhere
    sim: BatchedSim | None = None

    @cached_property  # resolved once per step, not once per term
    def xp(self):
        """The array namespace of this step's arrays (NumPy or torch)."""
        return namespace(self.state.base_pos)

    @property
    def contact(self) -> Array:
        return self.state.foot_force > self.params.contact_threshold

    @property
    def stance(self) -> Array:
        return (self.phase < self.params.stance_fraction) | self.standing[:, None]


def track_lin_vel_xy_exp(c: RewardContext) -> Array:
    xp = c.xp
    err = xp.sum((c.state.base_lin_vel[:, :2] - c.command[:, :2]) ** 2, axis=1)
    return xp.exp(-err / c.params.tracking_sigma)


def track_ang_vel_z_exp(c: RewardContext) -> Array:
    err = (c.command[:, 2] - c.state.base_ang_vel[:, 2]) ** 2
    return c.xp.exp(-err / c.params.tracking_sigma)


def lin_vel_z_l2(c: RewardContext) -> Array:
    return c.state.base_lin_vel[:, 2] ** 2


def ang_vel_xy_l2(c: RewardContext) -> Array:
    return c.xp.sum(c.state.base_ang_vel[:, :2] ** 2, axis=1)


def dof_torques_l2(c: RewardContext) -> Array:
    """The table's formula: sum_j |qdot_j| |tau_j| (mechanical power)."""
    xp = c.xp
    return xp.sum(xp.abs(c.state.joint_vel) * xp.abs(c.state.torque), axis=1)


def dof_acc_l2(c: RewardContext) -> Array:
    return c.xp.sum(c.state.joint_acc**2, axis=1)


def dof_vel_l2(c: RewardContext) -> Array:
    return c.xp.sum(c.state.joint_vel**2, axis=1)


def action_rate_l2(c: RewardContext) -> Array:
    return c.xp.sum((c.action - c.last_action) ** 2, axis=1)


def undesired_contacts(c: RewardContext) -> Array:
    """Hip, thigh or shin touching anything (> F*), plus feet struck laterally above the
    strike threshold: the section's foot-strike cost counted as events, as the table does."""
    xp = c.xp
    legs = xp.sum(c.state.leg_contact_force > c.params.contact_threshold, axis=1)
    strikes = xp.sum(c.state.foot_lateral_force > c.params.strike_threshold, axis=1)
    return as_float(legs + strikes, c.state.base_pos)


def feet_strike(c: RewardContext) -> Array:
    """The section's r_strike = sum_i |F_i^xy| in newtons (weight 0 by default)."""
    return c.xp.sum(c.state.foot_lateral_force, axis=1)


def contact_no_vel(c: RewardContext) -> Array:
    xp = c.xp
    speed2 = xp.sum(c.state.foot_vel**2, axis=2)
    return xp.sum(speed2 * c.contact, axis=1)


def _deviation(c: RewardContext, ids: Array) -> Array:
    xp = c.xp
    return xp.sum(xp.abs(c.state.joint_pos[:, ids] - c.default_joint_pos[ids]), axis=1)


def joint_deviation_hip(c: RewardContext) -> Array:
    return _deviation(c, c.hip_ids)


def joint_deviation_arms(c: RewardContext) -> Array:
    return _deviation(c, c.arm_ids)


def joint_deviation_torso(c: RewardContext) -> Array:
    return _deviation(c, c.torso_ids)


def height_torso(c: RewardContext) -> Array:
    return (c.state.base_height - c.params.base_height_target) ** 2


def feet_clearance(c: RewardContext) -> Array:
    """Minus the section's swing-height cost, so the table's +1.0 weight penalises it:
    -sum_i (1 - C_i) ((z_i - h*) / h_scale)^2 tanh(kappa |v_i^xy|)."""
    xp, p = c.xp, c.params
    target = xp.where(c.standing, p.stand_height, p.swing_height)[:, None]
    err = ((c.state.foot_height - target) / p.clearance_scale) ** 2
    gate = xp.tanh(p.clearance_gate * xp.linalg.vector_norm(c.state.foot_vel[..., :2], axis=2))
    swing = 1.0 - as_float(c.contact, c.state.foot_height)
    return -xp.sum(swing * err * gate, axis=1)


def feet_slide(c: RewardContext) -> Array:
    xp = c.xp
    speed2 = xp.sum(c.state.foot_vel[..., :2] ** 2, axis=2)
    return xp.sum(speed2 * c.contact, axis=1)


def phase_contact(c: RewardContext) -> Array:
    """XNOR of detected contact and stance intent, summed over feet: 2 - sum |c_i - s_i|."""
    return as_float(c.xp.sum(c.contact == c.stance, axis=1), c.state.base_pos)


def stand_still(c: RewardContext) -> Array:
    xp = c.xp
    dev = xp.sum(xp.abs(c.state.joint_pos - c.default_joint_pos), axis=1)
    return dev * c.standing


def feet_flat(c: RewardContext) -> Array:
    """1 - exp(-k sum_i C_i |pitch_i|): the table's weight -1.0 makes it the section's cost."""
    xp = c.xp
    tilt = xp.sum(xp.abs(c.state.foot_pitch) * c.contact, axis=1)
    return 1.0 - xp.exp(-c.params.flat_feet_k * tilt)


def flat_orientation_l2(c: RewardContext) -> Array:
    return c.xp.sum(c.state.projected_gravity[:, :2] ** 2, axis=1)


def dof_pos_limits(c: RewardContext) -> Array:
    xp, q = c.xp, c.state.joint_pos
    over = xp.clip(q - c.joint_upper, min=0.0) + xp.clip(c.joint_lower - q, min=0.0)
    return xp.sum(over, axis=1)


def alive(c: RewardContext) -> Array:
    return as_float(~c.terminated, c.command)


def termination_penalty(c: RewardContext) -> Array:
    return as_float(c.terminated, c.command)


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
) -> tuple[Array, dict[str, Array]]:
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
            value = namespace(value).where(value < 0, penalty_scale * value, value)
        terms[name] = value
    after_clip = unclipped | {"termination_penalty"} if only_positive else frozenset()
    xp = namespace(ctx.command)
    total = outside = xp.zeros(
        ctx.command.shape[0], dtype=ctx.command.dtype, device=device_of(ctx.command)
    )
    for name, value in terms.items():
        if name in after_clip:
            outside = outside + value
        else:
            total = total + value
    if only_positive:
        total = xp.clip(total, min=0.0)
    return total + outside, terms
