"""The VecEnv with real MuJoCo physics: episode bookkeeping, terminations, non-finite states,
and a long random-action rollout on the mixed terrain."""

from __future__ import annotations

import math

import numpy as np
import pytest
import torch
from rsl_rl.env import VecEnv

from lca.task.rewards import REWARD_TERMS

from .conftest import MIXED, STAND

J = 29
K = 5
FRAME = 2 * J + 6
DT = 0.02
GROUPS = ("policy", "height", "critic", "critic_height")
# The most a terminal step can earn: both tracking terms, both feet agreeing with the phase.
MAX_POSITIVE_STEP = (1.0 + 1.0 + 0.5 * 2) * DT


def critic_frames(obs) -> np.ndarray:
    x = obs["critic"].numpy()
    return x[:, : K * FRAME].reshape(len(x), K, FRAME)


def assert_fresh(env, obs, ids: np.ndarray) -> None:
    """Reset envs: at their tile centre (+- 0.1 m), upright, history = K copies of one frame."""
    ids = np.asarray(ids)
    if ids.size == 0:
        return
    for group in ("policy", "critic"):
        x = obs[group].numpy()[ids, : K * FRAME].reshape(len(ids), K, FRAME)
        np.testing.assert_array_equal(x, np.repeat(x[:, :1], K, axis=1))
    qpos = env.sim.qpos[ids]
    assert np.abs(qpos[:, :2] - env.sim.env_origin[ids]).max() <= 0.1 + 1e-9
    np.testing.assert_array_equal(qpos[:, 4:6], 0.0)  # spawn orientation is a pure yaw
    assert (env.episode_length_buf.numpy()[ids] == 0).all()


def assert_finite(obs, reward) -> None:
    for g in GROUPS:
        assert torch.isfinite(obs[g]).all(), g
    assert torch.isfinite(reward).all()


# ---- a robot that stands: exact episode bookkeeping ---------------------------------------
@pytest.fixture(scope="module")
def stand_env(make_env):
    # only_positive_rewards off: the logged terms must then add up to the returned reward
    return make_env(
        *STAND,
        "task.episode_length_s=0.5",
        "task.action_clip=0.2",
        "task.only_positive_rewards=false",
    )


def test_joint_groups_and_soft_limits(stand_env):
    _, env = stand_env
    names = env.scene.joint_names
    assert [names[i] for i in env.hip_ids] == [
        "left_hip_roll_joint",
        "left_hip_yaw_joint",
        "right_hip_roll_joint",
        "right_hip_yaw_joint",
    ]
    assert [names[i] for i in env.torso_ids] == [
        "waist_yaw_joint",
        "waist_roll_joint",
        "waist_pitch_joint",
    ]
    assert len(env.arm_ids) == 14
    assert all(any(p in names[i] for p in ("shoulder", "elbow", "wrist")) for i in env.arm_ids)
    # soft limits: the middle 95 % of each hinge range
    lo, hi = env.scene.model.jnt_range[1:].T
    knee = names.index("left_knee_joint")
    width = hi[knee] - lo[knee]
    assert env.joint_lower[knee] == pytest.approx(lo[knee] + 0.025 * width)
    assert env.joint_upper[knee] == pytest.approx(hi[knee] - 0.025 * width)
    np.testing.assert_allclose(env.joint_upper - env.joint_lower, 0.95 * (hi - lo))


def test_time_out_ends_every_episode_after_episode_length(stand_env):
    _, env = stand_env
    env.reset_all()  # fresh episodes, whatever earlier tests did with the shared env
    n = env.num_envs
    assert isinstance(env, VecEnv)
    assert env.max_episode_length == 25  # 0.5 s at 50 Hz
    rewards = []
    for k in range(1, 26):
        obs, reward, done, extras = env.step(torch.zeros(n, J))
        assert_finite(obs, reward)
        rewards.append(reward.numpy().astype(np.float64))
        if k < 25:
            assert not done.any(), k
            assert not extras["time_outs"].any(), k
            assert (env.episode_length_buf.numpy() == k).all()
            assert not any(key.startswith("Episode_Reward/") for key in extras["log"])
    assert done.dtype == torch.long
    np.testing.assert_array_equal(done.numpy(), 1)
    assert extras["time_outs"].all()
    assert_fresh(env, obs, np.arange(n))

    log = extras["log"]
    assert log["Episode_Termination/time_out"] == 1.0
    assert log["Episode_Termination/fall"] == 0.0
    assert log["Episode_Termination/nonfinite_total"] == 0.0
    episode = {k.removeprefix("Episode_Reward/"): v for k, v in log.items() if "Reward/" in k}
    assert set(episode) == set(REWARD_TERMS)
    # 25 steps alive: 0.15 * 1 * 0.02 each; never terminated
    assert episode["alive"] == pytest.approx(0.15 * DT * 25, rel=1e-12)
    assert episode["termination_penalty"] == 0.0
    assert episode["feet_strike"] == 0.0  # weight 0
    # the logged term sums add up to the rewards returned over the episode (mean over envs)
    assert sum(episode.values()) == pytest.approx(np.sum(rewards, axis=0).mean(), abs=1e-4)


def test_actions_are_clipped_and_applied_around_the_default_pose(stand_env):
    _, env = stand_env
    n = env.num_envs
    action = np.full((n, J), 0.5)
    action[:, 3] = -0.7
    action[:, 4] = 0.1
    obs = env.step(torch.as_tensor(action, dtype=torch.float32))[0]
    clipped = np.clip(action, -0.2, 0.2)  # task.action_clip=0.2
    np.testing.assert_allclose(env.sim.ctrl, env.default_joint_pos + 0.25 * clipped, atol=1e-7)
    applied = obs["policy"].numpy()[:, K * FRAME + 3 : K * FRAME + 3 + J]
    np.testing.assert_allclose(applied, clipped, atol=1e-7)


def test_fall_terminates_with_the_penalty(stand_env):
    _, env = stand_env
    n = env.num_envs
    length = int(env.episode_length_buf[2])
    resets = env.nonfinite_resets
    tilt = 1.2  # rad about x: beyond max_tilt = 1.0
    env.sim.qpos[2, 3:7] = [math.cos(tilt / 2), math.sin(tilt / 2), 0.0, 0.0]
    obs, reward, done, extras = env.step(torch.zeros(n, J))
    assert_finite(obs, reward)
    expected = np.zeros(n, dtype=np.int64)
    expected[2] = 1
    np.testing.assert_array_equal(done.numpy(), expected)
    assert not extras["time_outs"].any()
    assert env.nonfinite_resets == resets
    log = extras["log"]
    assert log["Episode_Termination/fall"] == 1.0
    assert log["Episode_Termination/time_out"] == 0.0
    assert log["Episode_Reward/termination_penalty"] == pytest.approx(-200.0 * DT)
    assert log["Episode_Reward/alive"] == pytest.approx(0.15 * DT * length)  # 0 at the fall
    assert reward[2] <= -200.0 * DT + MAX_POSITIVE_STEP
    assert_fresh(env, obs, np.array([2]))


# ---- mixed terrain: non-finite states and a long rollout ----------------------------------
@pytest.fixture(scope="module")
def mixed_env(make_env):
    return make_env(*MIXED)


def test_vec_env_interface(mixed_env):
    cfg, env = mixed_env
    assert isinstance(env, VecEnv)
    assert env.num_envs == 8
    assert env.num_actions == J
    assert env.max_episode_length == 1000  # 20 s at 50 Hz, the paper's episode
    assert env.dt == pytest.approx(DT)
    assert [env.sim.env_tile[i] for i in range(8)] == [0, 1, 2, 3, 0, 1, 2, 3]


def test_non_finite_states_are_reset_and_counted(mixed_env):
    _, env = mixed_env
    n = env.num_envs
    before = critic_frames(env.get_observations())
    resets = env.nonfinite_resets
    env.sim.qvel[3, 8] = np.nan  # a joint velocity
    env.sim.qvel[5, 0] = np.inf  # the base's x velocity
    env.sim.qpos[6, 2] = np.nan  # the base height
    obs, reward, done, extras = env.step(torch.zeros(n, J))
    broken = np.array([3, 5, 6])
    assert_finite(obs, reward)
    expected = np.zeros(n, dtype=np.int64)
    expected[broken] = 1
    np.testing.assert_array_equal(done.numpy(), expected)
    assert not extras["time_outs"].any()
    assert env.nonfinite_resets == resets + 3
    log = extras["log"]
    assert log["Episode_Termination/nonfinite_total"] == float(resets + 3)
    assert log["Episode_Termination/fall"] == 0.0  # counted apart from falls
    assert log["Episode_Reward/termination_penalty"] == pytest.approx(-200.0 * DT)
    assert (reward.numpy()[broken] <= -200.0 * DT + MAX_POSITIVE_STEP).all()
    assert np.isfinite(env.sim.qpos).all() and np.isfinite(env.sim.qvel).all()
    assert_fresh(env, obs, broken)
    # the other envs carry on: their history shifted by one frame
    ok = np.setdiff1d(np.arange(n), broken)
    np.testing.assert_array_equal(critic_frames(obs)[ok, 1:], before[ok, :-1])


@pytest.mark.slow  # a multi-second rollout
def test_random_rollout_on_mixed_terrain_runs_clean(mixed_env):
    _, env = mixed_env
    n = env.num_envs
    gen = torch.Generator().manual_seed(0)
    resets = env.nonfinite_resets
    obs = env.get_observations()
    length = env.episode_length_buf.numpy().copy()
    dones = time_outs = 0
    for _ in range(1000):
        prev = critic_frames(obs)
        actions = 0.3 * torch.randn(n, J, generator=gen)
        obs, reward, done, extras = env.step(actions)
        assert_finite(obs, reward)
        d = done.numpy().astype(bool)
        t = extras["time_outs"].numpy()
        assert set(np.unique(done.numpy())) <= {0, 1}
        assert not (t & ~d).any()
        new_length = env.episode_length_buf.numpy().copy()
        np.testing.assert_array_equal(new_length, np.where(d, 0, length + 1))
        assert new_length.max() < env.max_episode_length
        assert (length[t] + 1 == env.max_episode_length).all()
        length = new_length
        np.testing.assert_array_equal(critic_frames(obs)[~d, 1:], prev[~d, :-1])
        if d.any():
            assert_fresh(env, obs, np.flatnonzero(d))
            logged = {k for k in extras["log"] if k.startswith("Episode_Reward/")}
            assert logged == {f"Episode_Reward/{name}" for name in REWARD_TERMS}
            assert all(math.isfinite(v) for v in extras["log"].values())
        dones += int(d.sum())
        time_outs += int(t.sum())
    assert dones >= n  # random actions make robots fall; every fall resets
    assert env.nonfinite_resets == resets  # small random actions never break the physics


@pytest.mark.parametrize(
    "dof",
    [
        8,
        0,
    ],
)
def test_huge_velocity_reset_by_mujoco_is_detected(mixed_env, dof):
    """A finite velocity above mjMAXVAL (1e10) makes MuJoCo reset the data to qpos0 (the world
    origin, off the env's tile) during the step; the env must treat it as non-finite."""
    _, env = mixed_env
    n = env.num_envs
    resets = env.nonfinite_resets
    env.sim.qvel[1, dof] = 1e11
    obs, reward, done, _ = env.step(torch.zeros(n, J))
    assert_finite(obs, reward)
    assert done[1] == 1
    assert env.nonfinite_resets == resets + 1
    assert_fresh(env, obs, np.array([1]))


@pytest.mark.parametrize("perception", [False, True])
def test_without_the_critic_the_actor_sees_the_same(make_env, perception):
    """Evaluation turns the critic's observations off (`observe_critic`): the actor's
    observations stay bit for bit what they are with them, step after step."""
    envs = [make_env(*MIXED, "task.observations.noise=true")[1] for _ in range(2)]
    envs[1].observe_critic = False
    obs = []
    for env in envs:
        env.set_perception(perception)
        env.reseed(3)
        obs.append(env.reset_all())
    actions = torch.from_numpy(np.random.default_rng(0).uniform(-1, 1, (4, 8, J))).float()
    for step in range(len(actions) + 1):
        assert set(obs[1].keys()) == {"policy", "height"}
        for group in ("policy", "height"):
            torch.testing.assert_close(obs[1][group], obs[0][group], rtol=0, atol=0)
        if perception:
            assert obs[1]["height"].abs().sum() > 0
        if step < len(actions):
            obs = [env.step(actions[step])[0] for env in envs]
