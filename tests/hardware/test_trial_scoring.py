"""Hardware-trial scoring against scripted bases whose goal crossings are known: success,
signed lateral drift and time are exact, and nothing counts after a fall or a time-out."""

from __future__ import annotations

import math

import numpy as np

from lca.evaluate.hardware import score_trials

DT = 0.02
GOAL_X = 2.0
START_Y = np.array([0.0, 0.1, -0.2, 0.0, 0.3])


def scripted(steps: int):
    """Five trials: 0 walks at 0.5 m/s drifting +1 mm/step (crosses at step 199, t = 4 s);
    1 falls at step 50; 2 times out at step 100 and is then teleported past the goal;
    3 reaches the goal on the step it falls; 4 walks at 1 m/s drifting -2 mm/step
    (crosses at step 99, t = 2 s)."""
    for step in range(steps):
        t = (step + 1) * DT
        x = np.array([0.5 * t, 0.5 * t, 0.5 * t, 0.0, 1.0 * t])
        y = START_Y + np.array([0.001, 0.0, 0.0, 0.0, -0.002]) * (step + 1)
        terminated = np.zeros(5, bool)
        time_out = np.zeros(5, bool)
        terminated[1] = step == 50
        time_out[2] = step == 100
        if step > 100:
            x[2] = GOAL_X + 1.0
        if step == 30:
            x[3], terminated[3] = GOAL_X + 0.1, True
        yield (
            step,
            {
                "base_pos": np.stack([x, y, np.full(5, 0.75)], axis=1),
                "terminated": terminated,
                "time_out": time_out,
            },
        )


def test_scripted_trials_score_exactly() -> None:
    out = score_trials(scripted(400), START_Y, GOAL_X, DT)
    assert out["success"].tolist() == [True, False, False, False, True]
    assert out.loc[0, "time_s"] == 200 * DT and math.isclose(out.loc[0, "drift_m"], 0.200)
    assert out.loc[4, "time_s"] == 100 * DT and math.isclose(out.loc[4, "drift_m"], -0.200)
    assert out.loc[[1, 2, 3], ["drift_m", "time_s"]].isna().all().all()


def test_a_trial_not_reaching_the_goal_in_time_fails() -> None:
    out = score_trials(scripted(150), START_Y, GOAL_X, DT)  # trial 0 needs 200 steps
    assert out["success"].tolist() == [False, False, False, False, True]
