"""The hardware protocol in simulation: task configs, a smoke run of
`python -m lca.hardware` on a freshly trained run, and the hardware table in the report."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from _cli import REPO

from lca.config import compose
from lca.evaluate.hardware import task_config
from lca.hardware.__main__ import main as hardware_main
from lca.report.__main__ import main as report_main
from lca.report.hardware_table import HARDWARE_ROWS, hardware_rows, hardware_table

pytestmark = pytest.mark.slow  # trains, evaluates or runs a stage: see README

TASKS = ["stair_ascent", "soft_ledge"]


def trials(task_success_drift: dict[str, list[tuple[bool, float]]]) -> pd.DataFrame:
    rows = []
    for task, results in task_success_drift.items():
        for i, (ok, drift) in enumerate(results):
            rows.append({"task": task, "trial": i, "success": ok, "drift_m": drift})
    return pd.DataFrame(rows)


# ---- units ------------------------------------------------------------------------------


def test_task_config_is_the_paper_protocol():
    cfg = compose(["scale=smoke", "hardware.trials=3"])
    c = task_config(cfg)
    assert c.task.num_envs == 3
    assert c.task.episode_length_s == cfg.hardware.time_limit_s
    assert c.task.reset.yaw_range == 0 and c.task.reset.base_xy_noise == 0
    assert list(c.task.commands.lin_vel_x) == [0.3, 0.3]
    assert list(c.task.commands.lin_vel_y) == [0.0, 0.0]
    assert list(c.task.commands.ang_vel_z) == [0.0, 0.0]
    assert c.task.commands.standing_fraction == 0
    assert not c.task.randomization.enabled
    assert c.perception.source == "deployment" and c.perception.rate_hz == 30.0
    assert len(c.perception.cameras) == 2
    assert cfg.perception.source == "privileged"  # the input config is left alone


def test_hardware_table_counts_successes_and_reports_the_precision_of_successes_only():
    per_policy = {
        "Two-Stage MLP": trials(
            {
                "stair_ascent": [
                    (True, 0.04),
                    (True, 0.06),
                    (False, 9.0),
                    (True, 0.05),
                    (True, 0.05),
                ],
                "soft_ledge": [(False, np.nan)] * 5,
            }
        ),
        "Blind": trials(
            {
                "stair_ascent": [
                    (True, 0.2),
                    (False, np.nan),
                    (True, 0.4),
                    (False, 3.0),
                    (True, 0.3),
                ],
                "soft_ledge": [(True, 0.1)] * 5,
            }
        ),
        "Two-Stage CNN": trials(
            {"stair_ascent": [(True, 0.1)] * 5, "soft_ledge": [(True, 0.2)] * 4 + [(False, 1.0)]}
        ),
        "One-Stage MLP": trials(
            {"stair_ascent": [(False, np.nan)] * 5, "soft_ledge": [(True, 0.3)] + [(False, 0)] * 4}
        ),
    }
    table, latex = hardware_table(per_policy)
    got = table.set_index(["policy", "task"])
    assert got.loc[("Two-Stage MLP", "stair_ascent"), "successes"] == 4
    # precision: mean |d - mean(d)| over successes, worked by hand
    assert got.loc[("Two-Stage MLP", "stair_ascent"), "track_mad_m"] == pytest.approx(0.005)
    assert got.loc[("Two-Stage MLP", "stair_ascent"), "mean_abs_drift_m"] == pytest.approx(0.05)
    assert np.isnan(got.loc[("Two-Stage MLP", "soft_ledge"), "track_mad_m"])
    assert got.loc[("Blind", "stair_ascent"), "track_mad_m"] == pytest.approx(0.2 / 3)
    assert got.loc[("One-Stage MLP", "soft_ledge"), "track_mad_m"] == 0.0  # one success
    assert (table.trials == 5).all()
    lines = {line.split(" & ")[0].strip(): line for line in latex.splitlines() if " & " in line}
    assert lines["Two-Stage MLP"].split(" & ")[1:] == ["4/5", "0.005", "0/5", "-- \\\\"]
    assert lines["Blind"].split(" & ")[1:] == ["3/5", "0.067", "5/5", "0.000 \\\\"]
    assert lines["Two-Stage CNN"].split(" & ")[1:] == ["5/5", "0.000", "4/5", "0.000 \\\\"]
    assert lines["One-Stage MLP"].split(" & ")[1:] == ["0/5", "--", "1/5", "0.000 \\\\"]
    assert "Track (m" in latex and "mean absolute deviation" in latex
    # Rows in the paper's order, whatever order the policies come in; tasks in the paper's.
    order = [line.split(" & ")[0].strip() for line in latex.splitlines() if " & " in line]
    policies = [p for p in order if p in per_policy]
    assert policies == HARDWARE_ROWS == ["Blind", "One-Stage MLP", "Two-Stage CNN", "Two-Stage MLP"]
    assert latex.index("Stair Ascent") < latex.index("Soft Ledge")


def test_hardware_rows_per_task():
    rows = hardware_rows(trials({"hinged_ledge": [(True, 0.1), (False, 5.0), (True, 0.3)]}))
    assert rows.to_dict("records") == [
        {
            "task": "hinged_ledge",
            "successes": 2,
            "trials": 3,
            "track_mad_m": pytest.approx(0.1),
            "mean_abs_drift_m": pytest.approx(0.2),
        }
    ]


# ---- smoke run of the protocol ----------------------------------------------------------


@pytest.fixture(scope="module")
def trained_run(tmp_path_factory) -> Path:
    root = tmp_path_factory.mktemp("hardware_runs")
    cmd = [
        sys.executable,
        "run.py",
        "scale=smoke",
        "logger=none",
        "torch_threads=1",
        "eval.units=2",
        "eval.episodes=1",
        "eval.steps=10",
        f"runs_root={root}",
    ]
    done = subprocess.run(cmd, cwd=REPO, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    runs = [p for p in root.iterdir() if (p / "config.yaml").exists()]
    assert len(runs) == 1
    assert list((runs[0] / "checkpoints").glob("final_*.pt"))
    return runs[0]


@pytest.fixture(scope="module")
def hardware_csv(trained_run: Path) -> pd.DataFrame:
    args = [
        f"run_dir={trained_run}",
        "hardware.trials=2",
        "hardware.time_limit_s=1",
        f"hardware.tasks=[{','.join(TASKS)}]",
    ]
    assert hardware_main(args) == 0
    return pd.read_csv(trained_run / "hardware.csv")


def test_hardware_cli_writes_two_trials_per_task(hardware_csv: pd.DataFrame):
    t = hardware_csv
    assert list(t.columns) == ["task", "trial", "success", "drift_m", "time_s"]
    assert len(t) == 4
    assert t.task.tolist() == ["stair_ascent"] * 2 + ["soft_ledge"] * 2
    assert t.trial.tolist() == [0, 1, 0, 1]
    assert t.success.dtype == bool
    # the goal is >= 1.7 m away and the limit 1 s at 0.3 m/s: no trial can succeed here, so
    # every outcome is a failure without drift or time (scoring of successes: see
    # test_trial_scoring.py, with scripted bases)
    assert not t.success.any()
    assert t.drift_m.isna().all() and t.time_s.isna().all()


def test_hardware_cli_rejects_a_missing_run_dir(capsys):
    assert hardware_main([]) == 2
    assert "usage" in capsys.readouterr().err


def test_report_contains_the_hardware_table(trained_run: Path, hardware_csv, tmp_path: Path):
    out = tmp_path / "rep"
    assert report_main([str(trained_run), f"out={out}"]) == 0
    table = pd.read_csv(out / "hardware_table.csv")
    assert table.policy.unique().tolist() == ["Two-Stage CNN"]  # the default run's row
    assert table.task.tolist() == TASKS
    assert (table.trials == 2).all()
    expected = hardware_csv.groupby("task", sort=False).success.sum()
    assert table.successes.tolist() == expected.loc[TASKS].tolist()
    tex = (out / "hardware_table.tex").read_text()
    assert "Stair Ascent" in tex and "Soft Ledge" in tex and "Hinged Ledge" not in tex
    assert tex.count("/2") == 2
    page = (out / "index.html").read_text()
    assert 'id="hardware-table"' in page
    assert "stair_ascent" in page and "soft_ledge" in page
