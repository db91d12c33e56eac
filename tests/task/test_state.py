"""Frame helpers and what `read_state` reads from a standing robot."""

from __future__ import annotations

import math

import numpy as np
import pytest
import torch

from lca.task.state import pitch_of, quat_to_mat, read_state, yaw_of

from .conftest import STAND

G = 9.81


def quat(axis: str, angle: float) -> np.ndarray:
    v = {"x": [1, 0, 0], "y": [0, 1, 0], "z": [0, 0, 1]}[axis]
    return np.array([math.cos(angle / 2), *(math.sin(angle / 2) * np.array(v, float))])


def qmul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    w1, x1, y1, z1 = a
    w2, x2, y2, z2 = b
    return np.array(
        [
            w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2,
            w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
            w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
            w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2,
        ]
    )


def test_quat_to_mat_quarter_turn_about_z():
    m = quat_to_mat(quat("z", math.pi / 2))
    np.testing.assert_allclose(m, [[0, -1, 0], [1, 0, 0], [0, 0, 1]], atol=1e-12)
    m = quat_to_mat(np.stack([quat("x", 0.3), quat("y", -0.2)]))
    assert m.shape == (2, 3, 3)
    np.testing.assert_allclose(m[0] @ m[0].T, np.eye(3), atol=1e-12)
    np.testing.assert_allclose(m[1][:, 0], [math.cos(-0.2), 0, -math.sin(-0.2)], atol=1e-12)


def test_yaw_and_pitch_of_a_yawed_pitched_frame():
    # yaw 2.0 then pitch 0.3 about the new y-axis (toes down), then a roll that keeps x
    q = qmul(qmul(quat("z", 2.0), quat("y", 0.3)), quat("x", 0.4))
    assert yaw_of(q) == pytest.approx(2.0)
    assert pitch_of(q) == pytest.approx(0.3)
    assert pitch_of(quat("y", -0.1)) == pytest.approx(-0.1)
    assert pitch_of(quat("x", 0.7)) == pytest.approx(0.0, abs=1e-12)  # roll is not pitch
    np.testing.assert_allclose(yaw_of(np.stack([quat("z", -3.0), quat("z", 0.5)])), [-3.0, 0.5])


@pytest.fixture(scope="module")
def standing(make_env):
    cfg, env = make_env(*STAND)
    for _ in range(25):  # 0.5 s: the spawn drop has settled
        env.step(torch.zeros(env.num_envs, 29))
    return env, read_state(env.sim, env.contacts)


def test_standing_robot_is_carried_by_its_feet(standing):
    env, s = standing
    # nominal mass plus the randomised added base mass in [-1, 3] kg
    mass = env.scene.model.body_mass.sum()
    total = s.foot_force.sum(axis=1)
    # maxima over the substeps, so at least about the weight and not far above it
    assert (total > 0.9 * (mass - 1.0) * G).all(), total
    assert (total < 1.3 * (mass + 3.0) * G).all(), total
    assert (s.foot_force > 1.0).all()  # both feet in contact
    assert (s.foot_lateral_force < 100.0).all()  # no strikes while standing
    np.testing.assert_array_equal(s.leg_contact_force, 0.0)  # only the feet touch the ground


def test_standing_robot_geometry(standing):
    _, s = standing
    assert np.abs(s.foot_height).max() < 0.01  # sole sites on the ground
    assert np.abs(s.foot_pitch).max() < 0.05  # flat feet (< 3 degrees)
    assert ((s.base_height > 0.65) & (s.base_height < 0.85)).all()
    np.testing.assert_allclose(np.linalg.norm(s.projected_gravity, axis=1), 1.0, atol=1e-6)
    assert (s.projected_gravity[:, 2] < -0.99).all()
    assert np.abs(s.base_lin_vel).max() < 0.3 and np.abs(s.joint_vel).max() < 1.5  # swaying
