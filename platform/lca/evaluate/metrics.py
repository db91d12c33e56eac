"""The paper's metrics and their statistics over units.

Per episode: success (time limit reached without a fall or a non-finite state), contacts per
step (% of policy steps with a lateral foot impact > 100 N) and tracking error (mean
|u_xy - v_xy| in cm/s). A unit's value is the mean over its episodes; a cell's statistics
(mean, standard error, bootstrap CI) are over units.
"""

from __future__ import annotations

import warnings

import numpy as np
import pandas as pd
from scipy import stats

METRICS = {  # column labels, LaTeX-safe
    "success": "$R_{\\mathrm{succ}}$ (\\%, $\\uparrow$)",
    "contacts_per_step": "Contacts/step (\\%, $\\downarrow$)",
    "track_cm_s": "Track (cm/s, $\\downarrow$)",
}
CELL_KEYS = ["cell_terrain", "cell_difficulty"]


def episode_metrics(
    alive_steps: np.ndarray, impacts: np.ndarray, track_error_sum: np.ndarray, success: np.ndarray
) -> dict[str, np.ndarray]:
    """Per-episode metrics from per-env accumulators (all (U,) arrays)."""
    steps = np.maximum(alive_steps, 1)
    return {
        "success": 100.0 * success.astype(float),
        "steps": alive_steps.astype(int),
        "contacts_per_step": 100.0 * impacts / steps,
        "track_cm_s": 100.0 * track_error_sum / steps,
    }


def unit_values(episodes: pd.DataFrame, metric: str) -> pd.Series:
    """Mean of `metric` over each unit's episodes, indexed by unit."""
    return episodes.groupby("unit")[metric].mean().sort_index()


def _ci(
    samples: tuple[np.ndarray, ...],
    statistic,
    resamples: int,
    confidence: float,
    seed: int,
    paired: bool = False,
) -> tuple[float, float]:
    data = samples[0]
    if len(data) < 2 or all(np.ptp(s) == 0 for s in samples):
        value = float(statistic(*samples))
        return value, value
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = stats.bootstrap(
            samples,
            statistic,
            n_resamples=resamples,
            confidence_level=confidence,
            method="percentile",
            paired=paired,
            vectorized=True,
            random_state=np.random.default_rng(seed),
        )
    return float(res.confidence_interval.low), float(res.confidence_interval.high)


def _mean(x, axis=-1):
    return np.mean(x, axis=axis)


def describe(values: np.ndarray, resamples: int, confidence: float, seed: int) -> dict:
    """Mean, standard deviation across units (the paper's +-), standard error and
    percentile-bootstrap CI of the mean of unit values."""
    values = np.asarray(values, float)
    n = len(values)
    low, high = _ci((values,), _mean, resamples, confidence, seed)
    sd = float(values.std(ddof=1)) if n > 1 else 0.0
    return {
        "mean": float(values.mean()),
        "sd": sd,  # the spread across units: the paper's +-
        "se": sd / np.sqrt(n) if n > 1 else 0.0,
        "ci_low": low,
        "ci_high": high,
        "n_units": n,
    }


def summarize(
    episodes: pd.DataFrame,
    resamples: int,
    confidence: float,
    seed: int,
    by: list[str] = CELL_KEYS,
) -> pd.DataFrame:
    """One row per group (a cell by default) and metric: mean, se, ci_low, ci_high over units."""
    rows = []
    for key, group in episodes.groupby(by, sort=True):
        for metric in METRICS:
            row = describe(unit_values(group, metric).to_numpy(), resamples, confidence, seed)
            rows.append(
                {
                    **dict(zip(by, key, strict=True)),
                    "metric": metric,
                    "n_episodes": len(group),
                    **row,
                }
            )
    return pd.DataFrame(rows)


def paired_difference(
    a: pd.Series, b: pd.Series, resamples: int, confidence: float, seed: int
) -> dict:
    """Mean of a - b over units present in both (paired by unit), with a paired bootstrap CI."""
    common = a.index.intersection(b.index)
    x, y = a.loc[common].to_numpy(float), b.loc[common].to_numpy(float)

    def diff(u, v, axis=-1):
        return np.mean(u, axis=axis) - np.mean(v, axis=axis)

    low, high = _ci((x, y), diff, resamples, confidence, seed, paired=True)
    return {"diff": float(np.mean(x - y)), "ci_low": low, "ci_high": high, "n_units": len(common)}
