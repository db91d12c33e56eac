"""Training seeds as the unit of evidence (Agarwal et al., "Deep RL at the Edge of the
Statistical Precipice", NeurIPS 2021): per-seed values, the mean and interquartile mean (IQM)
across seeds, stratified bootstrap CIs (units resampled within each seed, seeds kept), the
probability of improvement and performance profiles.

These are rliable's definitions on NumPy/SciPy: rliable 1.2.0 cannot be installed beside
pandas 3 (it pins arch < 8, and arch 7 fails to import under pandas 3.1).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pandas as pd
from scipy.stats import trim_mean

from lca.evaluate.metrics import CELL_KEYS, unit_values

RESAMPLES, CONFIDENCE, SEED = 2000, 0.95, 0
PerSeed = list[np.ndarray]  # each seed's per-unit values


def iqm(values: np.ndarray, axis: int = -1) -> np.ndarray:
    """Interquartile mean: the mean of the middle 50 % (25 % trimmed from each end)."""
    return trim_mean(values, 0.25, axis=axis)


def per_seed_units(episodes: pd.DataFrame, metric: str) -> dict[int, np.ndarray]:
    """Each seed's per-unit values (a unit's mean over its episodes), by seed."""
    return {
        int(seed): unit_values(frame, metric).to_numpy(float)
        for seed, frame in episodes.groupby("seed")
    }


def stratified_bootstrap(
    per_seed: PerSeed, statistic: Callable, resamples: int, rng: np.random.Generator
) -> np.ndarray:
    """`statistic` of the per-seed means, (resamples, seeds) -> (resamples,), over
    resamples that draw each seed's units with replacement within that seed."""
    means = np.stack(
        [units[rng.integers(0, len(units), (resamples, len(units)))].mean(1) for units in per_seed],
        axis=1,
    )
    return statistic(means)


def across_seeds(
    per_seed: PerSeed, resamples: int = RESAMPLES, confidence: float = CONFIDENCE, seed: int = SEED
) -> dict[str, float]:
    """Mean and IQM of the per-seed means, each with a stratified bootstrap CI; with one seed
    there is no spread across seeds to estimate and the CIs are NaN."""
    values = np.array([units.mean() for units in per_seed])
    out = {"mean": float(values.mean()), "iqm": float(iqm(values))}
    tail = (1 - confidence) / 2 * 100
    for name, statistic in (("mean", lambda m: m.mean(1)), ("iqm", lambda m: iqm(m, 1))):
        if len(per_seed) < 2:
            low = high = np.nan
        else:
            rng = np.random.default_rng(seed)
            draws = stratified_bootstrap(per_seed, statistic, resamples, rng)
            low, high = np.percentile(draws, [tail, 100 - tail])
        out[f"{name}_ci_low"], out[f"{name}_ci_high"] = float(low), float(high)
    return out


def _beats(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """P(X > Y) + P(X = Y) / 2 for each row of x (R, n) against the same row of y (R, m)."""
    rows, m = y.shape
    # one sorted array for every row: shift row r by r * span so rows never interleave
    span = float(max(np.ptp(x), np.ptp(y), 1.0)) * 4 + 1.0
    low = min(x.min(), y.min())
    shift = np.arange(rows)[:, None] * span - low
    ys = np.sort(y + shift, axis=1).ravel()
    xs = (x + shift).ravel()
    below = np.searchsorted(ys, xs, side="left") - np.repeat(np.arange(rows) * m, x.shape[1])
    equal = np.searchsorted(ys, xs, side="right") - np.searchsorted(ys, xs, side="left")
    return ((below + equal / 2).reshape(x.shape) / m).mean(1)


def probability_of_improvement(x: PerSeed, y: PerSeed) -> float:
    """P(X > Y): the Mann-Whitney U of each seed's units over n * m, averaged over seeds
    (rliable's probability_of_improvement with seeds as its tasks)."""
    return float(np.mean([_beats(a[None], b[None])[0] for a, b in zip(x, y, strict=True)]))


def improvement_ci(
    x: PerSeed, y: PerSeed, resamples: int, confidence: float, seed: int
) -> tuple[float, float]:
    """Stratified bootstrap CI of the probability of improvement: both policies' units
    resampled within each seed."""
    rng = np.random.default_rng(seed)
    draws = np.zeros(resamples)
    for a, b in zip(x, y, strict=True):
        xa = a[rng.integers(0, len(a), (resamples, len(a)))]
        yb = b[rng.integers(0, len(b), (resamples, len(b)))]
        draws += _beats(xa, yb)
    draws /= len(x)
    tail = (1 - confidence) / 2 * 100
    low, high = np.percentile(draws, [tail, 100 - tail])
    return float(low), float(high)


def performance_profile(units: np.ndarray, taus: np.ndarray) -> np.ndarray:
    """The fraction of units scoring above each threshold tau."""
    return (units[None, :] > taus[:, None]).mean(1)


def seed_table(episodes: pd.DataFrame) -> pd.DataFrame:
    """One row per policy x cell x metric: each seed's value (`seed_<s>`), the mean and IQM
    across seeds with their CIs, and how many seeds and units per seed it rests on."""
    rows = []
    keys = ["policy", *CELL_KEYS]
    for (policy, terrain, difficulty), frame in episodes.groupby(keys, sort=False):
        for metric in ("success", "contacts_per_step", "track_cm_s"):
            by_seed = per_seed_units(frame, metric)
            row = {
                "policy": policy,
                "terrain": terrain,
                "difficulty": difficulty,
                "metric": metric,
                "n_seeds": len(by_seed),
                "n_units": min(len(u) for u in by_seed.values()),
                **across_seeds(list(by_seed.values())),
            }
            row.update({f"seed_{s}": float(u.mean()) for s, u in sorted(by_seed.items())})
            rows.append(row)
    return pd.DataFrame(rows)


IMPROVEMENT_METRICS = {"success": 1.0, "contacts_per_step": -1.0}  # sign of "better"


def improvement_table(runs: list) -> pd.DataFrame:
    """Two-stage against its one-stage twin (same actor and encoder) over the seeds both
    have, per cell: each seed's difference of means (positive: two-stage better), their mean,
    whether every seed's difference has the same nonzero sign (NaN with one seed), and
    P(two-stage better) with its stratified CI."""
    pools: dict[tuple, dict[int, pd.DataFrame]] = {}
    labels = {}
    for run in runs:
        if run.episodes is None or run.curriculum not in ("one", "two"):
            continue
        pools.setdefault((run.curriculum, run.actor, run.encoder), {})[run.seed] = run.episodes
        labels[(run.curriculum, run.actor, run.encoder)] = run.label
    rows = []
    for (curriculum, actor, encoder), two in sorted(pools.items()):
        one = pools.get(("one", actor, encoder))
        seeds = sorted(set(two) & set(one or {})) if curriculum == "two" else []
        if not seeds:
            continue
        cells = two[seeds[0]].groupby(CELL_KEYS).size().index
        for terrain, difficulty in cells:
            for metric, better in IMPROVEMENT_METRICS.items():
                x, y = [], []
                for s in seeds:
                    for side, pool in ((x, two), (y, one)):
                        frame = pool[s]
                        cell = frame[
                            (frame.cell_terrain == terrain) & (frame.cell_difficulty == difficulty)
                        ]
                        side.append(better * unit_values(cell, metric).to_numpy(float))
                diffs = [better * (a.mean() - b.mean()) for a, b in zip(x, y, strict=True)]
                signs = set(np.sign(diffs))
                rows.append(
                    {
                        "two_stage": labels[("two", actor, encoder)],
                        "one_stage": labels[("one", actor, encoder)],
                        "terrain": terrain,
                        "difficulty": difficulty,
                        "metric": metric,
                        "n_seeds": len(seeds),
                        "mean_diff": float(np.mean(diffs)),
                        # one nonzero sign in every seed (all-zero differences agree on nothing)
                        "sign_agrees": (len(signs) == 1 and 0 not in signs)
                        if len(seeds) > 1
                        else np.nan,
                        "p_improvement": probability_of_improvement(x, y),
                        **dict(
                            zip(
                                ("p_ci_low", "p_ci_high"),
                                improvement_ci(x, y, RESAMPLES, CONFIDENCE, SEED),
                                strict=True,
                            )
                        ),
                        **{f"diff_seed_{s}": float(d) for s, d in zip(seeds, diffs, strict=True)},
                    }
                )
    return pd.DataFrame(rows)
