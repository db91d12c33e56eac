"""End to end: a two-policy sweep through `python run.py -m` trains, evaluates and reports each
run, and the multirun's callback builds the sweep report with both policies and their pair."""

from __future__ import annotations

import json
from pathlib import Path

import pandas as pd
import pytest

from lca.evaluate.metrics import METRICS

from .helpers import cell_units, run_sweep

pytestmark = [pytest.mark.slow, pytest.mark.e2e]  # run.py end to end: see README

SWEEP = [
    "-m",
    "policy=one_mlp,two_mlp",
    "scale=smoke",
    "eval.units=2",
    "eval.episodes=1",
    "eval.steps=10",
    "eval.reference=[blind_flat]",  # the default job's reference rows (scale=smoke: none)
    "logger=none",
    "torch_threads=1",
    "sim.num_threads=1",
]
RUNS = {
    "one_mlp": "eval.episodes=1,eval.steps=10,eval.units=2,logger=none,policy=one_mlp,scale=smoke",
    "two_mlp": "eval.episodes=1,eval.steps=10,eval.units=2,logger=none,policy=two_mlp,scale=smoke",
}
LABELS = {"one_mlp": "One-Stage MLP", "two_mlp": "Two-Stage MLP"}
CELLS = 4


@pytest.fixture(scope="module")
def sweep(tmp_path_factory) -> Path:
    return run_sweep(tmp_path_factory.mktemp("sweep"), SWEEP, runs=2, timeout=300)


def test_runs_complete_with_results(sweep: Path) -> None:
    assert sorted(p.parent.name for p in sweep.glob("*/COMPLETE")) == sorted(RUNS.values())
    for name in RUNS.values():
        run = sweep / name
        marker = json.loads((run / "COMPLETE").read_text())
        assert marker["results"] == {"episodes": "results.parquet", "summary": "summary.csv"}
        assert marker["report"] == "report/index.html"
        results = pd.read_parquet(run / "results.parquet")
        assert len(results) == 2 * 1 * CELLS
        assert (results["run"] == name).all()
        assert len(pd.read_csv(run / "summary.csv")) == CELLS * len(METRICS)
        assert (run / "report" / "index.html").is_file()


def test_per_run_report(sweep: Path) -> None:
    for policy, name in RUNS.items():
        table = pd.read_csv(sweep / name / "report" / "sim_table.csv")
        # the run's own rows and the shipped reference policy's, on the same cells and seeds
        assert set(table["policy"]) == {LABELS[policy], "Blind (reference: blind_flat)"}
        assert len(table) == 2 * CELLS * len(METRICS)
        assert (table["n_units"] == 2).all()
        assert (sweep / name / "report" / "claim.csv").is_file()  # no pair in one run
        html = (sweep / name / "report" / "index.html").read_text()
        assert LABELS[policy] in html and 'href="../"' in html  # the run links to itself


def test_reference_policy_is_evaluated_once_for_the_sweep(sweep: Path) -> None:
    cached = list((sweep / ".reference").glob("blind_flat-*"))
    assert len(cached) == 1, cached  # one evaluation, reused by the second run
    results = pd.read_parquet(cached[0] / "results.parquet")
    assert len(results) == 2 * 1 * CELLS  # the sweep's eval sizes: 2 units x 1 episode
    html = (sweep / RUNS["one_mlp"] / "report" / "index.html").read_text()
    assert "Blind (reference: blind_flat)" in html


def test_sweep_report(sweep: Path) -> None:
    report = sweep / "report"
    for name in ("index.html", "sim_table.tex", "sim_table.csv", "claim.csv"):
        assert (report / name).is_file(), name
    assert (report / "training_rewards.png").stat().st_size > 0
    table = pd.read_csv(report / "sim_table.csv")
    assert list(table["policy"].drop_duplicates()) == ["One-Stage MLP", "Two-Stage MLP"]
    assert len(table) == 2 * CELLS * len(METRICS)
    assert (table["n_units"] == 2).all() and (table["n_seeds"] == 1).all()
    # the table's means are the runs' own summaries
    for policy, name in RUNS.items():
        summary = pd.read_csv(sweep / name / "summary.csv")
        mine = table[table.policy == LABELS[policy]]
        merged = mine.merge(
            summary,
            left_on=["terrain", "difficulty", "metric"],
            right_on=["cell_terrain", "cell_difficulty", "metric"],
        )
        assert len(merged) == CELLS * len(METRICS)
        assert merged["mean_x"].to_numpy() == pytest.approx(merged["mean_y"].to_numpy())
    html = (report / "index.html").read_text()
    for label in LABELS.values():
        assert label in html
    for name in RUNS.values():
        assert f'href="../{name}/"' in html


def test_sweep_claim(sweep: Path) -> None:
    claim = pd.read_csv(sweep / "report" / "claim.csv")
    assert len(claim) == CELLS * 2
    assert set(claim["two_stage"]) == {"Two-Stage MLP"}
    assert set(claim["one_stage"]) == {"One-Stage MLP"}
    assert set(claim["seed"]) == {0} and (claim["n_units"] == 2).all()
    two = pd.read_parquet(sweep / RUNS["two_mlp"] / "results.parquet")
    one = pd.read_parquet(sweep / RUNS["one_mlp"] / "results.parquet")
    for row in claim.itertuples():
        key = (row.terrain, row.difficulty, row.metric)
        diff = cell_units(two, *key) - cell_units(one, *key)
        assert row.diff == pytest.approx(diff.mean())


def test_common_random_numbers(sweep: Path) -> None:
    """Both policies met the same commands in every (cell, round, unit)."""
    keys = ["cell_terrain", "cell_difficulty", "episode", "unit"]
    one = pd.read_parquet(sweep / RUNS["one_mlp"] / "results.parquet").set_index(keys)
    two = pd.read_parquet(sweep / RUNS["two_mlp"] / "results.parquet").set_index(keys)
    assert one.index.sort_values().equals(two.index.sort_values())
    pd.testing.assert_series_equal(one["command_x"].sort_index(), two["command_x"].sort_index())
