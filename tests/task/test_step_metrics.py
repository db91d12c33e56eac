"""The evaluation metrics of one step, worked out by hand: tracking error is the planar
distance between command and base-frame velocity; a lateral impact is a foot's horizontal
force above 100 N (not at 100 N, not for the vertical force)."""

from __future__ import annotations

import numpy as np
import pytest

from lca.task.step_metrics import step_metrics

from .helpers import make_state

STRIKE_N = 100.0  # the paper's threshold


def metrics(**state_fields):
    n = 4
    state = make_state(n, **state_fields)
    command = np.array([[0.5, 0.0, 0.0], [0.3, 0.4, 0.0], [0.0, 0.0, 0.5], [0.6, 0.0, -0.2]])
    terminated = np.array([False, True, False, False])
    time_out = np.array([False, False, True, False])
    return step_metrics(state, command, terminated, time_out, STRIKE_N)


def test_tracking_error_is_the_planar_distance_in_the_base_frame() -> None:
    velocity = np.array([[0.2, 0.4, 9.0], [0.3, 0.4, 0.0], [0.0, 0.0, 0.0], [0.6, -0.8, 0.0]])
    world = np.full((4, 3), 5.0)  # the world-frame velocity must not be what is compared
    m = metrics(base_lin_vel=velocity, base_lin_vel_world=world)
    # (0.3, -0.4) -> 0.5; exact -> 0; yaw-only command -> 0; (0, 0.8) -> 0.8; vertical ignored
    np.testing.assert_allclose(m["track_error"], [0.5, 0.0, 0.0, 0.8])
    np.testing.assert_allclose(m["command_speed"], [0.5, 0.5, 0.0, 0.6])


def test_lateral_impacts_count_above_100_newtons_only() -> None:
    lateral = np.array([[100.0, 0.0], [100.1, 0.0], [0.0, 250.0], [99.0, 99.0]])
    vertical = np.full((4, 2), 500.0)  # standing weight does not count
    m = metrics(foot_lateral_force=lateral, foot_force=vertical)
    assert m["lateral_impact"].tolist() == [False, True, True, False]


def test_terminations_and_positions_are_copies() -> None:
    pos = np.arange(12, dtype=float).reshape(4, 3)
    m = metrics(base_pos=pos)
    assert m["terminated"].tolist() == [False, True, False, False]
    assert m["time_out"].tolist() == [False, False, True, False]
    np.testing.assert_array_equal(m["base_pos"], pos)
    pos[0, 0] = 99.0
    assert m["base_pos"][0, 0] == pytest.approx(0.0)
