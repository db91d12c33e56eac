"""Reward terms on hand-built states, each against a value worked out by hand.

Every term in `REWARD_TERMS` must have a `test_<name>` here (checked by
`test_every_reward_term_has_a_hand_computed_test`).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from lca.config import compose
from lca.task.config import RewardParams
from lca.task.rewards import REWARD_TERMS, RewardContext, compute_rewards
from lca.task.state import RobotState

from .helpers import DEFAULT_Q, J, make_state

HIP = np.array([1, 2, 7, 8])
TORSO = np.array([12, 13, 14])
ARMS = np.arange(15, 29)
PARAMS = RewardParams(
    tracking_sigma=0.25,
    gait_period=0.8,
    stance_fraction=0.55,
    contact_threshold=1.0,
    strike_threshold=100.0,
    base_height_target=0.77,
    swing_height=0.08,
    stand_height=0.0,
    clearance_scale=0.08,
    clearance_gate=10.0,
    flat_feet_k=25.0,
    soft_limit_factor=0.95,
)

# The paper's table "Nominal reward terms and weights for humanoid locomotion".
PAPER_WEIGHTS = {
    "track_lin_vel_xy_exp": 1.0,
    "track_ang_vel_z_exp": 1.0,
    "lin_vel_z_l2": -2.0,
    "ang_vel_xy_l2": -0.05,
    "dof_torques_l2": -2.0e-5,
    "dof_acc_l2": -2.5e-7,
    "dof_vel_l2": -1.0e-3,
    "action_rate_l2": -0.01,
    "undesired_contacts": -1.0,
    "contact_no_vel": -0.2,
    "joint_deviation_hip": -1.0,
    "joint_deviation_arms": -0.5,
    "joint_deviation_torso": -1.0,
    "height_torso": -50.0,
    "feet_clearance": 1.0,
    "feet_slide": -0.2,
    "phase_contact": 0.5,
    "stand_still": -0.1,
    "feet_flat": -1.0,
    "flat_orientation_l2": -1.0,
    "dof_pos_limits": -5.0,
    "alive": 0.15,
    "termination_penalty": -200.0,
}


def make_ctx(state: RobotState, **fields) -> RewardContext:
    n = len(state.base_pos)
    base = {
        "state": state,
        "command": np.tile([0.5, 0.0, 0.0], (n, 1)),
        "standing": np.zeros(n, dtype=bool),
        "phase": np.tile([0.2, 0.7], (n, 1)),  # left in stance, right in swing
        "action": np.zeros((n, J)),
        "last_action": np.zeros((n, J)),
        "default_joint_pos": DEFAULT_Q.copy(),
        "joint_lower": np.full(J, -1.0),
        "joint_upper": np.full(J, 1.0),
        "hip_ids": HIP,
        "arm_ids": ARMS,
        "torso_ids": TORSO,
        "terminated": np.zeros(n, dtype=bool),
        "params": PARAMS,
    }
    base.update({k: v if k == "params" else np.asarray(v) for k, v in fields.items()})
    return RewardContext(**base)


def term(name: str, ctx: RewardContext) -> np.ndarray:
    value = REWARD_TERMS[name](ctx)
    assert value.shape == (len(ctx.command),), name
    return value


def test_every_reward_term_has_a_hand_computed_test():
    missing = [n for n in REWARD_TERMS if f"test_{n}" not in globals()]
    assert not missing


def test_terms_are_finite_float_vectors_on_a_random_state():
    rng = np.random.default_rng(0)
    n = 4
    state = make_state(
        n,
        **{
            k: rng.normal(size=v.shape)
            for k, v in vars(make_state(n)).items()
            if k not in ("base_quat",)
        },
    )
    ctx = make_ctx(state, command=rng.normal(size=(n, 3)), phase=rng.random((n, 2)))
    for name in REWARD_TERMS:
        value = term(name, ctx)
        assert value.dtype == np.float64, name
        assert np.isfinite(value).all(), name


# ---- tracking ------------------------------------------------------------------------------
def test_track_lin_vel_xy_exp():
    state = make_state(base_lin_vel=[[0.5, 0.2, 9.0], [0.0, 0.0, -3.0]])
    ctx = make_ctx(state, command=[[0.3, -0.1, 0.7], [0.0, 0.0, 0.0]])
    # env 0: (0.2^2 + 0.3^2) = 0.13; z velocity and yaw command ignored. env 1: exact.
    np.testing.assert_allclose(term("track_lin_vel_xy_exp", ctx), [math.exp(-0.52), 1.0])


def test_track_ang_vel_z_exp():
    state = make_state(base_ang_vel=[[3.0, -2.0, 0.1], [0.0, 0.0, -0.5]])
    ctx = make_ctx(state, command=[[0.4, 0.4, 0.5], [0.0, 0.0, 0.5]])
    # env 0: (0.5 - 0.1)^2 = 0.16; env 1: (0.5 + 0.5)^2 = 1
    np.testing.assert_allclose(term("track_ang_vel_z_exp", ctx), [math.exp(-0.64), math.exp(-4)])


# ---- base motion ---------------------------------------------------------------------------
def test_lin_vel_z_l2():
    state = make_state(base_lin_vel=[[5.0, 5.0, 0.3], [0.0, 0.0, -2.0]])
    np.testing.assert_allclose(term("lin_vel_z_l2", make_ctx(state)), [0.09, 4.0])


def test_ang_vel_xy_l2():
    state = make_state(base_ang_vel=[[0.2, -0.4, 5.0], [0.0, 0.0, 7.0]])
    np.testing.assert_allclose(term("ang_vel_xy_l2", make_ctx(state)), [0.2, 0.0])


def test_height_torso():
    state = make_state(base_height=[0.67, 0.77])
    np.testing.assert_allclose(term("height_torso", make_ctx(state)), [0.01, 0.0], atol=1e-15)


def test_flat_orientation_l2():
    state = make_state(projected_gravity=[[0.6, 0.0, -0.8], [0.1, -0.2, -0.97]])
    np.testing.assert_allclose(term("flat_orientation_l2", make_ctx(state)), [0.36, 0.05])


# ---- joints --------------------------------------------------------------------------------
def test_dof_torques_l2():
    """The table's formula sum_j |qdot_j| |tau_j|, not a squared torque."""
    qd, tau = np.zeros((2, J)), np.zeros((2, J))
    qd[0, :3], tau[0, :3] = [2.0, -3.0, 0.0], [-5.0, 4.0, 100.0]
    qd[1, 5], tau[1, 5] = -0.5, -6.0
    state = make_state(joint_vel=qd, torque=tau)
    np.testing.assert_allclose(term("dof_torques_l2", make_ctx(state)), [22.0, 3.0])


def test_dof_acc_l2():
    acc = np.zeros((2, J))
    acc[0, :2] = [3.0, -4.0]
    state = make_state(joint_acc=acc)
    np.testing.assert_allclose(term("dof_acc_l2", make_ctx(state)), [25.0, 0.0])


def test_dof_vel_l2():
    qd = np.zeros((2, J))
    qd[0, :3] = [1.0, -2.0, 2.0]
    qd[1, -1] = 0.5
    state = make_state(joint_vel=qd)
    np.testing.assert_allclose(term("dof_vel_l2", make_ctx(state)), [9.0, 0.25])


def test_action_rate_l2():
    a, last = np.zeros((2, J)), np.zeros((2, J))
    a[0, :2], last[0, :2] = [1.0, 0.5], [0.5, 1.0]
    a[1], last[1] = 0.3, 0.3
    ctx = make_ctx(make_state(), action=a, last_action=last)
    np.testing.assert_allclose(term("action_rate_l2", ctx), [0.5, 0.0])


def _joint_offsets(ids: np.ndarray, deltas: list[float], other: float) -> np.ndarray:
    """Joint positions: default + deltas on `ids`, and `other` added on joint 0 if not in ids."""
    q = np.tile(DEFAULT_Q, (2, 1))
    q[0, ids[: len(deltas)]] += deltas
    if 0 not in ids:
        q[0, 0] += other
    return q


def test_joint_deviation_hip():
    q = _joint_offsets(HIP, [0.1, -0.2, 0.05], other=3.0)  # joint 0 (hip pitch) is not counted
    state = make_state(joint_pos=q)
    np.testing.assert_allclose(term("joint_deviation_hip", make_ctx(state)), [0.35, 0.0])


def test_joint_deviation_arms():
    q = _joint_offsets(ARMS, [0.4, -0.1], other=3.0)
    state = make_state(joint_pos=q)
    np.testing.assert_allclose(term("joint_deviation_arms", make_ctx(state)), [0.5, 0.0])


def test_joint_deviation_torso():
    q = _joint_offsets(TORSO, [-0.3], other=3.0)
    state = make_state(joint_pos=q)
    np.testing.assert_allclose(term("joint_deviation_torso", make_ctx(state)), [0.3, 0.0])


def test_stand_still():
    q = np.tile(DEFAULT_Q, (3, 1))
    q[:2, 0] += 0.2
    q[:2, 20] -= 0.1
    state = make_state(3, joint_pos=q)
    # env 0 standing and off the default pose; env 1 off the pose but walking; env 2 on it
    ctx = make_ctx(state, standing=np.array([True, False, True]))
    np.testing.assert_allclose(term("stand_still", ctx), [0.3, 0.0, 0.0], atol=1e-12)


def test_dof_pos_limits():
    """Only the part outside the soft limits [-1, 1] counts."""
    q = np.zeros((3, J))
    q[0, :3] = [1.2, -1.5, 0.99]
    q[1, :] = 1.0  # exactly on the limit
    q[2, 4] = -0.999
    state = make_state(3, joint_pos=q)
    np.testing.assert_allclose(term("dof_pos_limits", make_ctx(state)), [0.7, 0.0, 0.0])


# ---- contacts ------------------------------------------------------------------------------
def test_undesired_contacts():
    """Leg bodies above F* = 1 N, plus feet struck laterally above 100 N, counted as events."""
    legs = np.array(
        [
            [0.5, 1.5, 0.0, 200.0, 1.0, 0.0],  # 1.5 and 200 count; exactly 1.0 does not
            [0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
            [2.0, 2.0, 2.0, 2.0, 2.0, 2.0],
        ]
    )
    lateral = np.array([[150.0, 99.0], [100.0, 100.1], [0.0, 0.0]])
    foot = np.full((3, 2), 500.0)  # large vertical foot forces do not count
    state = make_state(3, leg_contact_force=legs, foot_lateral_force=lateral, foot_force=foot)
    np.testing.assert_allclose(term("undesired_contacts", make_ctx(state)), [3.0, 1.0, 6.0])


def test_feet_strike():
    lateral = np.array([[150.0, 30.0], [0.0, 0.0]])
    state = make_state(foot_lateral_force=lateral)
    np.testing.assert_allclose(term("feet_strike", make_ctx(state)), [180.0, 0.0])


def test_contact_no_vel():
    vel = np.array([[[1.0, 2.0, 2.0], [3.0, 0.0, 0.0]], [[1.0, 0.0, 0.0], [0.0, 0.0, 0.5]]])
    force = np.array([[50.0, 0.0], [0.5, 20.0]])  # env 1 left: below F*, not a contact
    state = make_state(foot_vel=vel, foot_force=force)
    # env 0: left |v|^2 = 9 in contact, right moving in the air; env 1: right 0.25
    np.testing.assert_allclose(term("contact_no_vel", make_ctx(state)), [9.0, 0.25])


def test_feet_slide():
    vel = np.array([[[0.3, 0.4, 5.0], [1.0, 1.0, 0.0]], [[0.0, 0.0, 3.0], [0.0, 0.0, 0.0]]])
    force = np.array([[50.0, 0.0], [50.0, 50.0]])
    state = make_state(foot_vel=vel, foot_force=force)
    # only planar speed of feet in contact: env 0 0.25 (z ignored, right foot in the air)
    np.testing.assert_allclose(term("feet_slide", make_ctx(state)), [0.25, 0.0])


# ---- gait ----------------------------------------------------------------------------------
@pytest.mark.parametrize(
    ("phase", "standing", "force", "expected"),
    [
        # left stance (0.2 < 0.55), right swing (0.7)
        ((0.2, 0.7), False, (50.0, 0.0), 2.0),  # both agree
        ((0.2, 0.7), False, (0.0, 50.0), 0.0),  # both disagree
        ((0.2, 0.7), False, (50.0, 50.0), 1.0),  # right in contact during swing
        ((0.2, 0.7), False, (0.0, 0.0), 1.0),  # left in the air during stance
        ((0.2, 0.7), False, (1.0, 0.0), 1.0),  # 1.0 N is not above F* = 1 N
        ((0.2, 0.7), False, (1.01, 0.0), 2.0),
        ((0.55, 0.05), False, (0.0, 50.0), 2.0),  # phi = tau is swing
        # standing: both feet are stance, double support is rewarded
        ((0.2, 0.7), True, (50.0, 50.0), 2.0),
        ((0.2, 0.7), True, (50.0, 0.0), 1.0),
        ((0.7, 0.2), True, (0.0, 0.0), 0.0),
    ],
)
def test_phase_contact(phase, standing, force, expected):
    state = make_state(1, foot_force=[force])
    ctx = make_ctx(state, phase=np.array([phase]), standing=np.array([standing]))
    assert term("phase_contact", ctx)[0] == expected


def test_feet_clearance():
    """-sum (1 - C) ((z - h*) / 0.08)^2 tanh(10 |v_xy|), h* = 0.08 walking, 0 standing."""
    height = np.array([[0.3, 0.0], [0.5, 0.5], [0.04, 0.04], [0.16, 0.08]])
    vel = np.zeros((4, 2, 3))
    vel[0] = [[1.0, 0.0, 0.0], [0.1, 0.0, 0.0]]
    vel[1] = [[0.0, 0.0, 1.0], [0.0, 0.0, -1.0]]  # feet not moving in the plane
    vel[2] = [[0.3, 0.4, 0.0], [0.0, 0.5, 0.0]]
    vel[3] = [[0.0, 0.2, 0.0], [0.3, 0.0, 0.0]]
    force = np.array([[50.0, 0.0], [0.0, 0.0], [0.0, 0.0], [0.0, 0.0]])
    state = make_state(4, foot_height=height, foot_vel=vel, foot_force=force)
    ctx = make_ctx(state, standing=np.array([False, False, True, False]))
    expected = [
        -math.tanh(1.0),  # left in contact: 0; right ((0 - 0.08)/0.08)^2 = 1, gate tanh(1)
        0.0,  # in the air, but no planar motion
        -2 * 0.25 * math.tanh(5.0),  # standing: target 0, ((0.04)/0.08)^2 = 0.25 per foot
        -math.tanh(2.0),  # left 1.0 * tanh(2); right exactly at the swing height
    ]
    np.testing.assert_allclose(term("feet_clearance", ctx), expected, atol=1e-15)


def test_feet_flat():
    """1 - exp(-25 sum_i C_i |pitch_i|)."""
    pitch = np.array([[0.02, 0.5], [-0.01, 0.03], [0.4, -0.4]])
    force = np.array([[50.0, 0.0], [50.0, 50.0], [0.0, 0.5]])
    state = make_state(3, foot_pitch=pitch, foot_force=force)
    expected = [1 - math.exp(-0.5), 1 - math.exp(-1.0), 0.0]
    np.testing.assert_allclose(term("feet_flat", make_ctx(state)), expected)


# ---- episode -------------------------------------------------------------------------------
def test_alive():
    ctx = make_ctx(make_state(3), terminated=np.array([True, False, False]))
    np.testing.assert_array_equal(term("alive", ctx), [0.0, 1.0, 1.0])


def test_termination_penalty():
    ctx = make_ctx(make_state(3), terminated=np.array([True, False, True]))
    np.testing.assert_array_equal(term("termination_penalty", ctx), [1.0, 0.0, 1.0])


# ---- weighting -----------------------------------------------------------------------------
def test_compute_rewards_multiplies_each_term_by_weight_and_dt():
    state = make_state(base_lin_vel=[[0.0, 0.0, 0.3], [0.0, 0.0, 0.0]])
    ctx = make_ctx(state, terminated=np.array([True, False]))
    weights = {"alive": 0.15, "lin_vel_z_l2": -2.0, "termination_penalty": -200.0, "dof_vel_l2": 0}
    total, terms = compute_rewards(ctx, weights, dt=0.02)
    assert set(terms) == set(weights)
    np.testing.assert_allclose(terms["alive"], [0.0, 0.003])
    np.testing.assert_allclose(terms["lin_vel_z_l2"], [-0.0036, 0.0], atol=1e-15)
    np.testing.assert_allclose(terms["termination_penalty"], [-4.0, 0.0])
    np.testing.assert_array_equal(terms["dof_vel_l2"], [0.0, 0.0])
    np.testing.assert_allclose(total, [-4.0036, 0.003])
    # per second of simulated time: a 4x shorter step gives a 4x smaller reward
    total_fast, _ = compute_rewards(ctx, weights, dt=0.005)
    np.testing.assert_allclose(total_fast, total / 4)


def test_only_positive_rewards_clips_all_but_the_termination_penalty():
    # env 0: falls with net-negative terms; env 1: net-negative, alive; env 2: net-positive
    state = make_state(3, base_lin_vel=[[0.0, 0.0, 0.3], [0.0, 0.0, 0.3], [0.0, 0.0, 0.0]])
    ctx = make_ctx(state, terminated=np.array([True, False, False]))
    weights = {"alive": 0.15, "lin_vel_z_l2": -2.0, "termination_penalty": -200.0}
    total, terms = compute_rewards(ctx, weights, dt=0.02, only_positive=True)
    # env 0: max(0 - 0.0036, 0) - 4; env 1: max(0.003 - 0.0036, 0); env 2: 0.003
    np.testing.assert_allclose(total, [-4.0, 0.0, 0.003])
    np.testing.assert_allclose(terms["lin_vel_z_l2"], [-0.0036, -0.0036, 0.0], atol=1e-15)
    plain, _ = compute_rewards(ctx, weights, dt=0.02)
    np.testing.assert_allclose(plain, [-4.0036, 0.003 - 0.0036, 0.003])


def test_unclipped_terms_are_added_after_the_clip():
    # env 1 is net-negative and alive: clipped to 0 unless its lin_vel_z cost is unclipped
    state = make_state(3, base_lin_vel=[[0.0, 0.0, 0.3], [0.0, 0.0, 0.3], [0.0, 0.0, 0.0]])
    ctx = make_ctx(state, terminated=np.array([True, False, False]))
    weights = {"alive": 0.15, "lin_vel_z_l2": -2.0, "termination_penalty": -200.0}
    unclipped = frozenset({"lin_vel_z_l2"})
    total, _ = compute_rewards(ctx, weights, dt=0.02, only_positive=True, unclipped=unclipped)
    # env 0: max(0, 0) - 0.0036 - 4; env 1: max(0.003, 0) - 0.0036; env 2: 0.003
    np.testing.assert_allclose(total, [-4.0036, 0.003 - 0.0036, 0.003])
    # without the clip the listed terms change nothing: the sum is the plain one
    plain, _ = compute_rewards(ctx, weights, dt=0.02, unclipped=unclipped)
    np.testing.assert_allclose(plain, compute_rewards(ctx, weights, dt=0.02)[0])


def test_compute_rewards_without_terms_is_zero():
    total, terms = compute_rewards(make_ctx(make_state(3)), {}, dt=0.02)
    assert terms == {}
    np.testing.assert_array_equal(total, np.zeros(3))


# ---- configuration -------------------------------------------------------------------------
@pytest.fixture(scope="module")
def task_cfg():
    return compose([]).task


def test_configured_weights_equal_the_paper_table(task_cfg):
    weights = {k: float(v) for k, v in task_cfg.rewards.items()}
    assert set(weights) == set(PAPER_WEIGHTS) | {"feet_strike"}
    for name, weight in PAPER_WEIGHTS.items():
        assert weights[name] == pytest.approx(weight, rel=1e-12, abs=0), name
    # the section's raw lateral force sum is off: the table counts strikes instead
    assert weights["feet_strike"] == 0.0
    assert set(weights) == set(REWARD_TERMS)


def test_configured_reward_params_equal_the_paper(task_cfg):
    p = task_cfg.reward_params
    assert p.tracking_sigma == 0.25
    assert p.gait_period == 0.8
    assert p.stance_fraction == 0.55
    assert p.contact_threshold == 1.0
    assert p.strike_threshold == 100.0
    assert p.base_height_target == 0.77
    assert p.flat_feet_k == 25.0
    assert task_cfg.commands.standing_epsilon == 5e-3


def test_penalty_scale_multiplies_negative_contributions_only():
    cfg = compose(["scale=smoke"])
    state = make_state(2, base_height=np.array([0.6, 0.77]))
    ctx = RewardContext(
        state=state,
        command=np.array([[0.5, 0.0, 0.0], [0.0, 0.0, 0.0]]),
        standing=np.array([False, True]),
        phase=np.zeros((2, 2)),
        action=np.ones((2, 29)),
        last_action=np.zeros((2, 29)),
        default_joint_pos=np.zeros(29),
        joint_lower=-np.ones(29),
        joint_upper=np.ones(29),
        hip_ids=np.array([1, 2]),
        arm_ids=np.array([15, 16]),
        torso_ids=np.array([12]),
        terminated=np.array([True, False]),
        params=cfg.task.reward_params,
    )
    weights = dict(cfg.task.rewards)
    full, full_terms = compute_rewards(ctx, weights, dt=0.02)
    scaled, terms = compute_rewards(ctx, weights, dt=0.02, penalty_scale=0.25)
    for name, value in full_terms.items():
        expected = np.where(value < 0, 0.25 * value, value)
        np.testing.assert_allclose(terms[name], expected, err_msg=name)
    assert (scaled > full).all()
    assert full_terms["termination_penalty"][0] < 0  # the termination penalty is a penalty
