"""End to end: two policies x three training seeds through `python run.py -m`: one run per
seed, and a sweep report with per-seed values, the IQM, CIs across seeds and the probability
of improvement."""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import pytest

from .helpers import run_sweep

pytestmark = [pytest.mark.slow, pytest.mark.e2e]

SWEEP = [
    "-m",
    "policy=one_mlp,two_mlp",
    "seed=0,1,2",
    "scale=smoke",
    "eval.units=3",
    "eval.episodes=1",
    "eval.steps=10",
    "eval.reference=[]",
    "logger=none",
    "torch_threads=1",
    "sim.num_threads=1",
]


@pytest.fixture(scope="module")
def sweep(tmp_path_factory) -> Path:
    return run_sweep(tmp_path_factory.mktemp("seeds"), SWEEP, runs=6, timeout=600)


def test_one_run_per_seed(sweep: Path) -> None:
    runs = sorted(p.parent.name for p in sweep.glob("*/COMPLETE"))
    assert len(runs) == 6
    for seed in (0, 1, 2):
        assert sum(f"seed={seed}" in name for name in runs) == 2, runs


def test_report_has_statistics_across_seeds(sweep: Path) -> None:
    report = sweep / "report"
    seeds = pd.read_csv(report / "seed_table.csv")
    assert set(seeds["policy"]) == {"One-Stage MLP", "Two-Stage MLP"}
    assert (seeds["n_seeds"] == 3).all() and (seeds["n_units"] == 3).all()
    for column in ("seed_0", "seed_1", "seed_2", "mean", "iqm", "iqm_ci_low", "iqm_ci_high"):
        assert seeds[column].notna().all(), column
    assert (seeds["iqm_ci_low"] <= seeds["iqm"] + 1e-9).all()
    improvement = pd.read_csv(report / "improvement.csv")
    assert (improvement["n_seeds"] == 3).all()
    assert improvement["p_improvement"].between(0, 1).all()
    assert {"diff_seed_0", "diff_seed_1", "diff_seed_2", "sign_agrees"} <= set(improvement)
    latex = (report / "sim_table.tex").read_text()
    assert "interquartile mean across training seeds" in latex
    html = (report / "index.html").read_text()
    assert 'id="seeds"' in html and "performance_profiles.png" in html
    assert (report / "performance_profiles.png").stat().st_size > 0
    assert list(report.glob("seeds_*.png"))
