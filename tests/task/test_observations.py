"""Proprioception frames, their noise and history; the observation groups of the env."""

from __future__ import annotations

import math

import numpy as np
import pytest
import torch

from lca.config import compose
from lca.task import observations
from lca.task.state import RobotState

from .conftest import STAND

J = 29
K = 5
FRAME = 2 * J + 6  # joint_pos, joint_vel, base_ang_vel, projected_gravity
# Paper table "Proprioception observation terms": (slice in a frame, noise half-width, scale)
OBS = compose(["scale=smoke"]).task.observations  # the declared terms of conf/task


def history_frame(state, default, terms, rng):
    """A history frame of `state` alone (the proprioception terms read nothing else)."""
    n = len(state.joint_pos)
    inputs = observations.ObsInputs(
        state, default, np.zeros((n, 3)), np.zeros((n, J)), np.zeros((n, 2)), np.zeros(n, bool)
    )
    return observations.build(inputs, terms, rng)


PAPER_TERMS = {
    "joint_pos": (slice(0, J), 0.01, 1.0),
    "joint_vel": (slice(J, 2 * J), 1.5, 0.05),
    "base_ang_vel": (slice(2 * J, 2 * J + 3), 0.2, 0.25),
    "projected_gravity": (slice(2 * J + 3, 2 * J + 6), 0.05, 1.0),
}
CMD_SCALE = np.array([2.0, 2.0, 0.25])


def random_state(n: int, seed: int = 0) -> RobotState:
    rng = np.random.default_rng(seed)
    g = rng.normal(size=(n, 3))
    return RobotState(
        base_pos=rng.normal(size=(n, 3)),
        base_quat=np.tile([1.0, 0.0, 0.0, 0.0], (n, 1)),
        base_lin_vel=rng.normal(size=(n, 3)),
        base_lin_vel_world=rng.normal(size=(n, 3)),
        base_ang_vel=rng.normal(size=(n, 3)),
        projected_gravity=g / np.linalg.norm(g, axis=1, keepdims=True),
        base_height=rng.normal(size=n),
        joint_pos=rng.normal(size=(n, J)),
        joint_vel=rng.normal(0, 5, size=(n, J)),
        joint_acc=rng.normal(size=(n, J)),
        torque=rng.normal(size=(n, J)),
        foot_pos=rng.normal(size=(n, 2, 3)),
        foot_vel=rng.normal(size=(n, 2, 3)),
        foot_pitch=rng.normal(size=(n, 2)),
        foot_height=rng.normal(size=(n, 2)),
        foot_force=rng.normal(size=(n, 2)),
        foot_lateral_force=rng.normal(size=(n, 2)),
        leg_contact_force=rng.normal(size=(n, 6)),
    )


# ---- terms ---------------------------------------------------------------------------------
def test_history_terms_match_the_paper_table():
    terms = observations.history_terms(OBS, J)
    assert [t.name for t in terms] == list(PAPER_TERMS)
    for t in terms:
        sl, noise, scale = PAPER_TERMS[t.name]
        assert t.dim == sl.stop - sl.start
        assert t.noise == noise, t.name
        assert t.scale == scale, t.name


def test_current_terms_layout():
    terms = observations.current_terms(OBS, J)
    assert [(t.name, t.dim) for t in terms] == [
        ("velocity_commands", 3),
        ("actions", J),
        ("phase", 2),
    ]
    assert tuple(terms[0].scale) == (2.0, 2.0, 0.25)
    assert all(t.noise == 0 for t in terms)


def test_noiseless_frame_by_hand():
    state = random_state(3)
    default = np.linspace(-0.5, 0.5, J)
    frame = history_frame(state, default, observations.history_terms(OBS, J), None)
    assert frame.shape == (3, FRAME)
    np.testing.assert_allclose(frame[:, :J], state.joint_pos - default)
    np.testing.assert_allclose(frame[:, J : 2 * J], 0.05 * state.joint_vel)
    np.testing.assert_allclose(frame[:, 2 * J : 2 * J + 3], 0.25 * state.base_ang_vel)
    np.testing.assert_allclose(frame[:, 2 * J + 3 :], state.projected_gravity)


def test_noisy_frame_differs_by_at_most_noise_times_scale():
    n = 2000
    state = random_state(n, seed=1)
    default = np.zeros(J)
    terms = observations.history_terms(OBS, J)
    rng = np.random.default_rng(5)
    noisy = history_frame(state, default, terms, rng)
    clean = history_frame(state, default, terms, None)
    for name, (sl, noise, scale) in PAPER_TERMS.items():
        diff = (noisy - clean)[:, sl]
        bound = noise * scale
        assert np.abs(diff).max() <= bound * (1 + 1e-9), name
        assert np.abs(diff).max() >= 0.99 * bound, name  # the full range is used
        # noise on the raw value, then scaled: U(-bound, bound) has std bound / sqrt(3)
        assert diff.std() == pytest.approx(bound / math.sqrt(3), rel=0.05), name
        assert abs(diff.mean()) < 0.05 * bound, name


def test_phase_features():
    phase = np.array([[0.25, 0.75], [0.0, 0.5], [0.6, 0.1], [0.3, 0.8]])
    standing = np.array([False, False, False, True])
    f = observations.phase_features(phase, standing)
    np.testing.assert_allclose(f[0], [1.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(f[1], [0.0, 1.0], atol=1e-12)
    np.testing.assert_allclose(f[2], [math.sin(1.2 * math.pi), math.cos(1.2 * math.pi)])
    np.testing.assert_array_equal(f[3], [0.0, 0.0])  # standing detection


# ---- history -------------------------------------------------------------------------------
def test_history_is_newest_first():
    h = observations.History(num_envs=2, length=3, dim=2)
    frames = [np.full((2, 2), float(i)) + np.array([[0.0, 0.5], [10.0, 10.5]]) for i in range(5)]
    h.push(frames[0])
    h.push(frames[1])
    np.testing.assert_array_equal(h.flat()[0], [1.0, 1.5, 0.0, 0.5, 0.0, 0.0])
    h.push(frames[2])
    h.push(frames[3])
    flat = h.flat()
    assert flat.shape == (2, 6)
    np.testing.assert_array_equal(flat[0], [3.0, 3.5, 2.0, 2.5, 1.0, 1.5])  # newest block first
    np.testing.assert_array_equal(flat[1], [13.0, 13.5, 12.0, 12.5, 11.0, 11.5])


def test_history_fill_repeats_the_first_frame_of_reset_envs_only():
    h = observations.History(num_envs=3, length=4, dim=2)
    for i in range(4):
        h.push(np.full((3, 2), float(i)))
    before = h.flat().copy()
    first = np.arange(6, dtype=float).reshape(3, 2) + 100
    h.fill(np.array([1]), first)
    flat = h.flat()
    np.testing.assert_array_equal(flat[1], np.tile([102.0, 103.0], 4))
    np.testing.assert_array_equal(flat[[0, 2]], before[[0, 2]])


# ---- env: proprioception noise and layout --------------------------------------------------
@pytest.fixture(scope="module")
def noisy_env(make_env):
    return make_env(*STAND, "difficulty=hard", "task.observations.height_dropout=0")


def _frames(obs, group: str) -> np.ndarray:
    x = obs[group].numpy()
    return x[:, : K * FRAME].reshape(len(x), K, FRAME)


def test_env_group_shapes(noisy_env):
    _, env = noisy_env
    obs = env.get_observations()
    n = env.num_envs
    assert obs["policy"].shape == (n, K * FRAME + 3 + J + 2) == (n, 354)
    assert obs["critic"].shape == (n, 357)
    assert obs["height"].shape == (n, 1, 11, 11)
    assert obs["critic_height"].shape == (n, 1, 16, 16)
    for v in obs.values():
        assert v.dtype == torch.float32


def test_env_policy_noise_is_bounded_per_term_and_current_terms_are_clean(noisy_env):
    _, env = noisy_env
    n = env.num_envs
    diffs = []
    obs = env.get_observations()
    for step in range(4):
        diff = _frames(obs, "policy") - _frames(obs, "critic")
        diffs.append(diff[:, 0] if step else diff.reshape(-1, FRAME))
        pol, cri = obs["policy"].numpy(), obs["critic"].numpy()
        np.testing.assert_array_equal(pol[:, K * FRAME :], cri[:, K * FRAME : 354])
        obs = env.step(torch.zeros(n, J))[0]
    diff = np.concatenate(diffs)
    for name, (sl, noise, scale) in PAPER_TERMS.items():
        bound = noise * scale
        assert np.abs(diff[:, sl]).max() <= bound + 1e-6, name
        assert np.abs(diff[:, sl]).max() >= 0.8 * bound, name


def test_env_critic_frame_reads_the_simulation(noisy_env):
    _, env = noisy_env
    n = env.num_envs
    action = np.full((n, J), 0.05)
    env.commands.value[0] = 0.0  # env 0 is commanded to stand
    obs = env.step(torch.as_tensor(action, dtype=torch.float32))[0]
    sim = env.sim
    newest = _frames(obs, "critic")[:, 0]
    f32 = {"rtol": 1e-5, "atol": 1e-6}
    np.testing.assert_allclose(newest[:, :J], sim.qpos[:, 7:] - env.default_joint_pos, **f32)
    np.testing.assert_allclose(newest[:, J : 2 * J], 0.05 * sim.qvel[:, 6:], **f32)
    np.testing.assert_allclose(
        newest[:, 2 * J : 2 * J + 3], 0.25 * sim.sensor("imu_ang_vel"), **f32
    )
    np.testing.assert_allclose(newest[:, 2 * J + 3 :], -sim.sensor("imu_up"), **f32)
    # a robot standing upright: gravity points down the body z-axis
    np.testing.assert_allclose(newest[:, 2 * J + 3 :], np.tile([0, 0, -1.0], (n, 1)), atol=0.1)

    cri = obs["critic"].numpy()
    current = cri[:, K * FRAME : K * FRAME + 3 + J + 2]
    np.testing.assert_allclose(current[:, :3], env.commands.value * CMD_SCALE, **f32)
    np.testing.assert_allclose(current[:, 3 : 3 + J], action, **f32)
    steps = env.episode_length_buf.numpy()
    angle = 2 * np.pi * np.mod(steps * 0.02 / 0.8, 1.0)
    walking = np.linalg.norm(env.commands.value, axis=1) >= 5e-3
    assert not walking[0]
    expected_phase = np.stack([np.sin(angle), np.cos(angle)], 1) * walking[:, None]
    np.testing.assert_allclose(current[:, 3 + J :], expected_phase, atol=1e-6)
    np.testing.assert_allclose(cri[:, -3:], sim.sensor("base_lin_vel_world"), **f32)


# ---- env: height maps ----------------------------------------------------------------------
def test_env_actor_map_noise_on_flat_ground_hard(noisy_env):
    """Flat ground: the actor map is pure U(-0.3, 0.3) noise minus its mean; the critic's is 0."""
    _, env = noisy_env
    obs = env.step(torch.zeros(env.num_envs, J))[0]
    h = obs["height"].numpy().reshape(env.num_envs, -1)
    assert (h != 0).all()  # dropout is off
    span = h.max(axis=1) - h.min(axis=1)
    assert span.max() <= 0.6 + 1e-6
    assert span.min() >= 0.45
    np.testing.assert_allclose(h.mean(axis=1), 0.0, atol=1e-6)
    assert h.std() == pytest.approx(0.3 / math.sqrt(3), rel=0.1)
    assert (obs["critic_height"].numpy() == 0).all()


@pytest.fixture(scope="module")
def blind_stairs_env(make_env):
    # a 1.0 m spawn platform: the 1.5 m critic grid sees the first steps of the pit
    return make_env(
        "scale=smoke", "terrain=stairs_up", "terrain.platform=1.0", "task.perception=false"
    )


def _assert_pit_map(critic_height: np.ndarray) -> None:
    m = critic_height[:, 0]
    assert (np.abs(m).reshape(len(m), -1).max(axis=1) > 0.05).all()
    # the four centre cells (0.05 m around the base) lie on the pit floor, the lowest level
    centre = m[:, 7:9, 7:9].reshape(len(m), -1)
    np.testing.assert_allclose(centre.min(axis=1), m.reshape(len(m), -1).min(axis=1))
    np.testing.assert_allclose(centre.max(axis=1), centre.min(axis=1), atol=1e-6)


def test_perception_off_zeroes_only_the_actor_map(blind_stairs_env):
    _, env = blind_stairs_env
    n = env.num_envs
    obs = env.get_observations()
    assert (obs["height"].numpy() == 0).all()
    _assert_pit_map(obs["critic_height"].numpy())

    env.set_perception(True)
    obs = env.step(torch.zeros(n, J))[0]
    h = obs["height"].numpy().reshape(n, -1)
    assert (np.abs(h).max(axis=1) > 0.05).all()
    _assert_pit_map(obs["critic_height"].numpy())

    env.set_perception(False)
    obs = env.step(torch.zeros(n, J))[0]
    assert (obs["height"].numpy() == 0).all()
    _assert_pit_map(obs["critic_height"].numpy())
