"""The deployment perception source end to end: ray-cast depth cameras on real MuJoCo scenes
-> merged point cloud -> filter -> the policy's `height` observation, at the camera rate."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from lca.config import compose
from lca.sim.depth_camera import CameraSpec, ray_directions
from lca.task import perception
from lca.task.env import LocomotionEnv
from lca.task.state import yaw_of

STAIRS = [
    "terrain=stairs_up",
    "terrain.platform=0.5",
    "task.reset.yaw_range=0",
    "task.reset.base_xy_noise=0",
    "perception=deployment",
    "scale=smoke",
]


def zeros(env: LocomotionEnv) -> torch.Tensor:
    return torch.zeros(env.num_envs, env.num_actions)


def height(obs) -> np.ndarray:
    return obs["height"].numpy().copy()


def new_frame(step: int, policy_hz: int = 50, camera_hz: int = 30) -> bool:
    """Exact (integer) test of whether floor(t * 30) advances at policy step `step`."""
    return step * camera_hz // policy_hz != (step - 1) * camera_hz // policy_hz


# ---- camera geometry --------------------------------------------------------------------


def angle(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.degrees(np.arccos(np.clip(a @ b, -1.0, 1.0))))


def test_straight_down_camera_centre_ray_points_down():
    spec = CameraSpec(body="pelvis", pos=[0, 0, 0], pitch_deg=90.0, rays_h=5, rays_w=7)
    dirs = ray_directions(spec).reshape(5, 7, 3)
    np.testing.assert_allclose(np.linalg.norm(dirs, axis=-1), 1.0)
    np.testing.assert_allclose(dirs[2, 3], [0.0, 0.0, -1.0], atol=1e-12)
    assert (dirs[..., 2] < 0).all()  # the whole fan looks down


@pytest.mark.parametrize("pitch, yaw", [(90.0, 0.0), (65.0, 0.0), (70.0, 180.0)])
def test_fan_spans_the_configured_field_of_view(pitch, yaw):
    spec = CameraSpec(
        body="pelvis", pos=[0, 0, 0], pitch_deg=pitch, yaw_deg=yaw, rays_h=9, rays_w=11
    )
    dirs = ray_directions(spec).reshape(9, 11, 3)
    assert angle(dirs[4, 0], dirs[4, -1]) == pytest.approx(spec.fov_h_deg, abs=1e-6)
    assert angle(dirs[0, 5], dirs[-1, 5]) == pytest.approx(spec.fov_v_deg, abs=1e-6)
    p, y = np.radians(pitch), np.radians(yaw)
    axis = [np.cos(p) * np.cos(y), np.cos(p) * np.sin(y), -np.sin(p)]
    np.testing.assert_allclose(dirs[4, 5], axis, atol=1e-12)


def test_deployment_cameras_look_behind_from_the_hips_and_ahead_from_the_chest():
    cfg = compose(["perception=deployment", "scale=smoke"])
    hip, chest = (CameraSpec(**c) for c in cfg.perception.cameras)
    assert (hip.body, chest.body) == ("pelvis", "torso_link")
    hip_axis = ray_directions(hip).mean(axis=0)
    chest_axis = ray_directions(chest).mean(axis=0)
    assert hip_axis[0] < 0 and hip_axis[2] < 0  # down and back
    assert chest_axis[0] > 0 and chest_axis[2] < 0  # down and ahead
    assert abs(hip_axis[1]) < 1e-9 and abs(chest_axis[1]) < 1e-9


# ---- flat floor -------------------------------------------------------------------------


@pytest.fixture(scope="module")
def flat_env() -> LocomotionEnv:
    return LocomotionEnv(compose(["perception=deployment", "terrain=flat", "scale=smoke"]))


def test_cameras_cover_the_grid_on_a_flat_floor(flat_env: LocomotionEnv):
    """The zero map below is not zero for lack of points: the cameras fill the grid."""
    env = flat_env
    points, valid = env.camera_map.cameras.capture()
    assert valid.mean() > 0.9
    np.testing.assert_allclose(points[valid][:, 2], 0.0, atol=0.05)
    state = env._state
    obs = env.task_cfg.observations
    _, filled = perception.min_height_grid(
        points,
        valid,
        state.base_pos[:, :2],
        yaw_of(state.base_quat),
        tuple(obs.actor_grid),
        obs.actor_spacing,
    )
    assert filled.mean(axis=1).min() > 0.9


def test_flat_floor_map_is_exactly_zero_for_every_env(flat_env: LocomotionEnv):
    env = flat_env
    for _ in range(5):
        obs, _, dones, _ = env.step(zeros(env))
        h = height(obs)
        assert h.shape == (env.num_envs, 1, 11, 11)
        assert np.abs(h).max() == 0
    assert not dones.any()


# ---- stairs -----------------------------------------------------------------------------


@pytest.fixture(scope="module")
def stairs_env() -> LocomotionEnv:
    return LocomotionEnv(compose(STAIRS))


def test_cameras_see_the_pit_stairs(stairs_env: LocomotionEnv):
    """On the 0.5 m bottom platform of a stairs_up pit the first riser is 0.25 m away on
    every side: the centre of the map reads below the mean, the outer ring above it."""
    env = stairs_env
    h = height(env.get_observations())[:, 0]
    assert env.perception
    for m in h:
        assert np.abs(m).max() > 0
        k = m / 0.05
        np.testing.assert_allclose(k, np.round(k), atol=1e-6)
        assert m.min() >= -1.0 and m.max() <= 1.0
        assert m[4:7, 4:7].mean() < 0 < np.r_[m[0], m[-1], m[:, 0], m[:, -1]].mean()
        assert m.max() - m.min() >= 0.1  # a 14-18 cm riser survives quantisation


@pytest.mark.slow  # a multi-second rollout
def test_map_only_changes_on_30hz_camera_frames(stairs_env: LocomotionEnv):
    env = stairs_env
    assert env.dt == pytest.approx(0.02) and env.perception_cfg.rate_hz == 30.0
    prev = height(env.reset_all())  # fresh episodes, whatever earlier tests did with the env
    assert (env.episode_length_buf == 0).all()
    changed_steps = []
    for step in range(1, 16):
        obs, _, dones, _ = env.step(zeros(env))
        assert not dones.any()
        h = height(obs)
        changed = [not np.array_equal(h[i], prev[i]) for i in range(env.num_envs)]
        if new_frame(step):
            changed_steps.append(step)
            assert any(changed), f"no env got a new map on camera frame step {step}"
        else:
            assert not any(changed), f"map changed between camera frames at step {step}"
        prev = h
    # 15 policy steps = 0.3 s: 9 new frames at 30 Hz (frame 0 came with the reset).
    assert changed_steps == [2, 4, 5, 7, 9, 10, 12, 14, 15]


def test_set_perception_zeroes_and_restores_the_camera_map(stairs_env: LocomotionEnv):
    env = stairs_env
    before = height(env.get_observations())
    assert np.abs(before).max() > 0
    env.set_perception(False)
    assert np.abs(height(env.get_observations())).max() == 0
    obs, *_ = env.step(zeros(env))
    assert np.abs(height(obs)).max() == 0
    env.set_perception(True)
    restored = height(env.get_observations())
    assert np.abs(restored).max() > 0
    k = restored / 0.05
    np.testing.assert_allclose(k, np.round(k), atol=1e-6)


def test_camera_frames_follow_floor_t_times_30_over_a_long_episode():
    cfg = compose(
        [
            "perception=deployment",
            "terrain=flat",
            "scale=smoke",
            "task.num_envs=2",
            "robot.natural_frequency_hz=30",  # stands passively: no resets for 210 steps
            "task.randomization.enabled=false",
        ]
    )
    env = LocomotionEnv(cfg)
    late = []
    for _ in range(210):
        env.step(zeros(env))
        steps = env.episode_length_buf.numpy()
        assert (steps == steps[0]).all()
        expected = steps * 30 // 50  # floor(t * 30) with t = steps / 50, exactly
        if not np.array_equal(env.camera_map.frame, expected):
            late.append(int(steps[0]))
    assert late == []
