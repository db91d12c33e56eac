"""Run-level statistics across training seeds, against hand-computed values and an
independent implementation written here."""

from __future__ import annotations

import itertools

import numpy as np
import pandas as pd
import pytest

from lca.report.seeds import (
    across_seeds,
    improvement_table,
    iqm,
    performance_profile,
    probability_of_improvement,
    seed_table,
    stratified_bootstrap,
)
from lca.report.tables import across_seed_count, sim_caption, wide_table


def test_iqm_of_known_numbers() -> None:
    # 8 values: the middle half is 3, 4, 5, 6
    assert iqm(np.array([1.0, 2, 3, 4, 5, 6, 7, 100])) == pytest.approx(4.5)
    assert iqm(np.array([5.0, 5, 5, 5])) == 5.0


def test_stratified_bootstrap_matches_an_independent_loop() -> None:
    rng = np.random.default_rng(0)
    per_seed = [rng.uniform(0, 1, 7), rng.uniform(2, 3, 5), rng.uniform(4, 5, 6)]
    ours = stratified_bootstrap(per_seed, lambda m: m.mean(1), 50, np.random.default_rng(9))
    # the same generator, one resample at a time: each seed's units drawn within that seed
    again = np.random.default_rng(9)
    draws = [again.integers(0, len(u), (50, len(u))) for u in per_seed]
    expected = [
        np.mean([u[d[r]].mean() for u, d in zip(per_seed, draws, strict=True)]) for r in range(50)
    ]
    np.testing.assert_allclose(ours, expected, rtol=1e-12)
    # each seed's mean stays within its own units' range, so their average stays in (2, 3)
    assert np.all((ours > 2) & (ours < 3))


def test_across_seeds_statistics_and_one_seed() -> None:
    per_seed = [np.full(10, 1.0), np.full(10, 2.0), np.full(10, 6.0)]
    out = across_seeds(per_seed)
    assert out["mean"] == pytest.approx(3.0)
    assert out["mean_ci_low"] == out["mean_ci_high"] == pytest.approx(3.0)  # no unit spread
    single = across_seeds([np.arange(10.0)])
    assert single["mean"] == single["iqm"] == 4.5
    assert np.isnan(single["mean_ci_low"]) and np.isnan(single["iqm_ci_high"])


def test_probability_of_improvement_known_cases() -> None:
    rng = np.random.default_rng(1)
    same = [rng.uniform(0, 1, 20) for _ in range(3)]
    assert probability_of_improvement(same, same) == pytest.approx(0.5)
    better = [u + 10 for u in same]
    assert probability_of_improvement(better, same) == 1.0
    assert probability_of_improvement(same, better) == 0.0
    # against the definition: pairs won plus half the ties, over all pairs, per seed
    x, y = [np.array([1.0, 2, 3])], [np.array([2.0, 2, 0])]
    pairs = list(itertools.product(x[0], y[0]))
    expected = np.mean([(a > b) + 0.5 * (a == b) for a, b in pairs])
    assert probability_of_improvement(x, y) == pytest.approx(expected)


def test_performance_profile() -> None:
    units = np.array([0.0, 50, 100, 100])
    np.testing.assert_allclose(
        performance_profile(units, np.array([-1, 0, 50, 99])), [1, 0.75, 0.5, 0.5]
    )


def _episodes(policy: str, seeds: dict[int, list[float]]) -> pd.DataFrame:
    rows = [
        {
            "policy": policy,
            "seed": s,
            "unit": f"{s}:{u}",
            "cell_terrain": "uneven",
            "cell_difficulty": "hard",
            "success": v,
            "contacts_per_step": 0.0,
            "track_cm_s": 10.0,
        }
        for s, values in seeds.items()
        for u, v in enumerate(values)
    ]
    return pd.DataFrame(rows)


def test_seed_table_rows_and_the_table_it_fills() -> None:
    episodes = pd.concat(
        [
            _episodes("Blind", {0: [100, 0], 1: [100, 100], 2: [0, 0]}),
            _episodes("Two-Stage MLP", {0: [100, 100], 1: [100, 100], 2: [100, 0]}),
        ]
    )
    table = seed_table(episodes)
    row = table[(table.policy == "Blind") & (table.metric == "success")].iloc[0]
    assert (row.seed_0, row.seed_1, row.seed_2) == (50.0, 100.0, 0.0)
    assert row.n_seeds == 3 and row.n_units == 2
    assert row["mean"] == pytest.approx(50.0) and row.iqm == pytest.approx(50.0)
    assert row.iqm_ci_low <= row.iqm <= row.iqm_ci_high
    assert across_seed_count(table) == 3 and "across training seeds" in sim_caption(3)
    long = table.assign(mean=table["mean"], sd=0.0)
    text, _ = wide_table(long, table)
    assert text.iloc[0, 0].startswith("50.00 [")  # the IQM with its CI
    # one seed: the unit-level table, and a caption that claims nothing across seeds
    one = seed_table(_episodes("Blind", {0: [100, 0]}))
    assert across_seed_count(one) == 1 and "seed" not in sim_caption(1)
    assert one[["mean_ci_low", "iqm_ci_low"]].isna().all().all()


class _Run:
    def __init__(self, curriculum, seed, values, label):
        self.curriculum, self.actor, self.encoder, self.seed = curriculum, "mlp", "mlp", seed
        self.label = label
        self.episodes = _episodes(label, {seed: values})


def test_improvement_per_seed_sign_and_probability() -> None:
    runs = [_Run("two", s, [100, 100, 100], "Two-Stage MLP") for s in (0, 1, 2)]
    runs += [_Run("one", s, [0, 100, 0], "One-Stage MLP") for s in (0, 1, 2)]
    table = improvement_table(runs)
    row = table[table.metric == "success"].iloc[0]
    assert row.n_seeds == 3 and bool(row.sign_agrees)
    assert [row.diff_seed_0, row.diff_seed_1, row.diff_seed_2] == pytest.approx([66.67] * 3, 0.01)
    # two-stage wins 6 of 9 pairs per seed and ties 3: (6 + 1.5) / 9
    assert row.p_improvement == pytest.approx(7.5 / 9)
    assert row.p_ci_low <= row.p_improvement <= row.p_ci_high
    single = improvement_table([r for r in runs if r.seed == 0])
    assert single.n_seeds.tolist() == [1, 1] and single.sign_agrees.isna().all()
