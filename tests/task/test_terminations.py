"""Fall and non-finite detection on hand-built states."""

from __future__ import annotations

import math

import numpy as np

from lca.task.config import TerminationConfig
from lca.task.terminations import TERMINATIONS, fell, non_finite

from .helpers import make_state

CFG = TerminationConfig(min_base_height=0.35, max_tilt=1.0, max_joint_vel=1000.0)


def gravity(tilt: float) -> list[float]:
    return [math.sin(tilt), 0.0, -math.cos(tilt)]


def test_fell_on_low_base_or_large_tilt():
    state = make_state(
        5,
        base_height=[0.77, 0.34, 0.36, 0.77, 0.77],
        projected_gravity=[gravity(0), gravity(0), gravity(0), gravity(0.95), gravity(1.05)],
    )
    np.testing.assert_array_equal(fell(state, CFG), [False, True, False, False, True])


def test_upside_down_is_a_fall():
    state = make_state(1, projected_gravity=[[0.0, 0.0, 1.0]])
    assert fell(state, CFG)[0]


def test_non_finite_any_field_or_runaway_joint_velocity():
    qd = np.zeros((5, 29))
    qd[3, 4] = 1000.5
    qd[4, 4] = -999.0
    state = make_state(5, joint_vel=qd)
    state.foot_force[1, 0] = np.nan
    state.base_quat[2, 0] = np.inf
    np.testing.assert_array_equal(non_finite(state, 1000.0), [False, True, True, True, False])


def test_termination_names():
    assert set(TERMINATIONS) == {"fall", "time_out", "non_finite"}
