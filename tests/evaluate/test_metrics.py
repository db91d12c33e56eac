"""The paper's metrics and their statistics on synthetic episode logs with known answers."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from lca.evaluate.metrics import (
    CELL_KEYS,
    METRICS,
    describe,
    episode_metrics,
    paired_difference,
    summarize,
    unit_values,
)

RESAMPLES, CONFIDENCE, SEED = 2000, 0.95, 0


def _stats(values, resamples=RESAMPLES, confidence=CONFIDENCE, seed=SEED) -> dict:
    return describe(np.asarray(values, float), resamples, confidence, seed)


# ---- per episode ------------------------------------------------------------------------


def test_episode_metrics_known_answers() -> None:
    # unit 0: 20 steps alive, timed out, 2 lateral impacts, |u - v| summed to 4.0 m/s
    # unit 1: fell after 10 steps with 5 impacts; unit 2: fell on its first step, no impact
    out = episode_metrics(
        alive_steps=np.array([20.0, 10.0, 1.0]),
        impacts=np.array([2.0, 5.0, 0.0]),
        track_error_sum=np.array([4.0, 1.0, 0.25]),
        success=np.array([True, False, False]),
    )
    np.testing.assert_array_equal(out["success"], [100.0, 0.0, 0.0])  # %
    np.testing.assert_array_equal(out["steps"], [20, 10, 1])
    np.testing.assert_allclose(out["contacts_per_step"], [10.0, 50.0, 0.0])  # % of steps
    np.testing.assert_allclose(out["track_cm_s"], [20.0, 10.0, 25.0])  # mean m/s -> cm/s


def test_episode_metrics_zero_steps_is_finite() -> None:
    out = episode_metrics(np.zeros(2), np.zeros(2), np.zeros(2), np.zeros(2, bool))
    for key in ("success", "contacts_per_step", "track_cm_s"):
        assert np.isfinite(out[key]).all() and (out[key] == 0).all(), key


# ---- per unit ---------------------------------------------------------------------------


def test_unit_values_average_episodes_per_unit() -> None:
    episodes = pd.DataFrame(
        {
            "unit": [2, 0, 1, 0, 2, 1, 0],
            "episode": [0, 0, 0, 1, 1, 1, 2],
            "success": [100.0, 100.0, 0.0, 0.0, 100.0, 0.0, 100.0],
            "track_cm_s": [10.0, 1.0, 4.0, 2.0, 30.0, 6.0, 6.0],
        }
    )
    success = unit_values(episodes, "success")
    assert list(success.index) == [0, 1, 2]
    np.testing.assert_allclose(success.to_numpy(), [200 / 3, 0.0, 100.0])
    np.testing.assert_allclose(unit_values(episodes, "track_cm_s").to_numpy(), [3.0, 5.0, 20.0])


# ---- over units -------------------------------------------------------------------------


def test_describe_mean_and_standard_error() -> None:
    values = [1.0, 2.0, 3.0, 4.0, 5.0]
    out = _stats(values)
    assert out["mean"] == pytest.approx(3.0)
    # sample standard deviation (ddof=1) sqrt(2.5), over sqrt(n)
    assert out["se"] == pytest.approx(np.sqrt(2.5) / np.sqrt(5))
    assert out["n_units"] == 5
    assert out["ci_low"] < out["mean"] < out["ci_high"]
    assert out["ci_low"] >= 1.0 and out["ci_high"] <= 5.0  # a bootstrap mean stays in range


def test_bootstrap_ci_contains_mean_and_shrinks_with_more_units() -> None:
    rng = np.random.default_rng(7)
    base = rng.normal(50.0, 10.0, 10)
    small = _stats(base)
    large = _stats(np.tile(base, 16))  # same distribution, 16x the units
    for out in (small, large):
        assert out["ci_low"] < out["mean"] < out["ci_high"]
    assert small["mean"] == pytest.approx(large["mean"])
    width_small = small["ci_high"] - small["ci_low"]
    width_large = large["ci_high"] - large["ci_low"]
    assert width_large < width_small / 2.5  # ~1/sqrt(16) = 1/4 of the width
    # with many units the percentile CI is close to mean +- 1.96 se
    assert width_large == pytest.approx(2 * 1.96 * large["se"], rel=0.15)


def test_bootstrap_ci_follows_confidence_and_seed() -> None:
    values = np.random.default_rng(3).normal(0.0, 1.0, 40)
    wide, narrow = _stats(values, confidence=0.95), _stats(values, confidence=0.5)
    assert narrow["ci_high"] - narrow["ci_low"] < wide["ci_high"] - wide["ci_low"]
    assert _stats(values, seed=11) == _stats(values, seed=11)  # reproducible


@pytest.mark.parametrize("values", [[42.0] * 6, [100.0] * 2, [3.5]])
def test_degenerate_data_zero_width_ci(values) -> None:
    out = _stats(values)
    assert out["mean"] == pytest.approx(values[0])
    assert out["se"] == 0.0
    assert out["ci_low"] == out["ci_high"] == pytest.approx(values[0])
    assert out["n_units"] == len(values)


# ---- per cell ---------------------------------------------------------------------------


def _synthetic_episodes() -> pd.DataFrame:
    """2 cells x 3 units x 2 episodes with hand-picked values."""
    rows = []
    cells = {
        ("stairs", "hard"): {"success": [[100, 0], [100, 100], [0, 0]], "base": 1.0},
        ("uneven", "medium"): {"success": [[100, 100], [100, 100], [100, 0]], "base": 5.0},
    }
    for (terrain, difficulty), spec in cells.items():
        for unit in range(3):
            for episode in range(2):
                rows.append(
                    {
                        "cell_terrain": terrain,
                        "cell_difficulty": difficulty,
                        "unit": unit,
                        "episode": episode,
                        "success": float(spec["success"][unit][episode]),
                        "steps": 20,
                        "contacts_per_step": spec["base"] + unit,  # units: base, +1, +2
                        "track_cm_s": 10 * spec["base"] + episode,  # episodes: +0, +1
                    }
                )
    return pd.DataFrame(rows)


def test_summarize_rows_per_cell_and_metric() -> None:
    episodes = _synthetic_episodes().sample(frac=1.0, random_state=0)  # order must not matter
    summary = summarize(episodes, RESAMPLES, CONFIDENCE, SEED)
    assert len(summary) == 2 * len(METRICS)
    assert list(summary[CELL_KEYS].drop_duplicates().itertuples(index=False, name=None)) == [
        ("stairs", "hard"),
        ("uneven", "medium"),
    ]
    assert (summary["n_units"] == 3).all() and (summary["n_episodes"] == 6).all()
    got = summary.set_index(["cell_terrain", "cell_difficulty", "metric"])
    expected_mean = {
        ("stairs", "hard", "success"): 50.0,  # units 50, 100, 0
        ("stairs", "hard", "contacts_per_step"): 2.0,  # units 1, 2, 3
        ("stairs", "hard", "track_cm_s"): 10.5,
        ("uneven", "medium", "success"): 250 / 3,  # units 100, 100, 50
        ("uneven", "medium", "contacts_per_step"): 6.0,
        ("uneven", "medium", "track_cm_s"): 50.5,
    }
    for key, mean in expected_mean.items():
        assert got.loc[key, "mean"] == pytest.approx(mean), key
    assert got.loc[("stairs", "hard", "success"), "se"] == pytest.approx(50 / np.sqrt(3))
    assert got.loc[("stairs", "hard", "contacts_per_step"), "se"] == pytest.approx(1 / np.sqrt(3))
    # every unit has the same mean tracking error: no spread, a zero-width CI
    track = got.loc[("stairs", "hard", "track_cm_s")]
    assert track["se"] == 0.0 and track["ci_low"] == track["ci_high"] == pytest.approx(10.5)
    for row in summary.itertuples():
        assert row.ci_low <= row.mean <= row.ci_high


# ---- paired comparisons -----------------------------------------------------------------


def test_paired_difference_recovers_a_constant_shift() -> None:
    units = pd.Index(range(20), name="unit")
    b = pd.Series(np.random.default_rng(1).normal(50.0, 20.0, 20), index=units)
    a = b + 3.0
    out = paired_difference(a, b, RESAMPLES, CONFIDENCE, SEED)
    assert out["diff"] == pytest.approx(3.0)
    assert out["ci_low"] == pytest.approx(3.0) and out["ci_high"] == pytest.approx(3.0)
    assert out["ci_low"] > 0  # excludes 0
    assert out["n_units"] == 20


def test_paired_difference_pairs_by_unit() -> None:
    """Unit-to-unit spread (sd 20) hides a +2 effect unpaired, not when paired by unit."""
    rng = np.random.default_rng(2)
    b = pd.Series(rng.normal(50.0, 20.0, 30), index=range(30))
    a = b + 2.0 + rng.normal(0.0, 0.5, 30)
    a_shuffled = a.sample(frac=1.0, random_state=5)  # pairing is by index, not position
    out = paired_difference(a_shuffled, b, RESAMPLES, CONFIDENCE, SEED)
    assert out["diff"] == pytest.approx(float((a - b).mean()))
    assert 0 < out["ci_low"] < out["diff"] < out["ci_high"] < 4.0
    # the same numbers compared unpaired are not distinguishable from zero
    unpaired_se = np.sqrt(a.var(ddof=1) / 30 + b.var(ddof=1) / 30)
    assert out["diff"] < 1.96 * unpaired_se


def test_paired_difference_uses_common_units_only() -> None:
    a = pd.Series([10.0, 20.0, 30.0, 99.0], index=[0, 1, 2, 7])
    b = pd.Series([5.0, 15.0, 25.0, -99.0], index=[2, 1, 0, 9])
    out = paired_difference(a, b, RESAMPLES, CONFIDENCE, SEED)
    assert out["n_units"] == 3
    assert out["diff"] == pytest.approx(((10 - 25) + (20 - 15) + (30 - 5)) / 3)


def test_paired_difference_identical_data_is_zero() -> None:
    a = pd.Series(np.random.default_rng(4).uniform(0.0, 100.0, 12))
    out = paired_difference(a, a.copy(), RESAMPLES, CONFIDENCE, SEED)
    assert out == {"diff": 0.0, "ci_low": 0.0, "ci_high": 0.0, "n_units": 12}
