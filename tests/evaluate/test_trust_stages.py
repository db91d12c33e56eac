"""Stages you can trust: only complete runs are reported (the others are listed with their
reason), `force=true` clears every old output, and every entry point takes the overrides
`run.py` takes, group options included."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys

import pandas as pd
import pytest
from omegaconf import OmegaConf

from lca.config import compose
from lca.evaluate.policy import load_run_config
from lca.pipeline import run_pipeline
from lca.report.build import build_report
from lca.store import RunDir

from .helpers import REPO, SMOKE, run_evaluate_cli, run_module, train_tiny_run

pytestmark = pytest.mark.slow  # trains, evaluates or runs a stage: see README


@pytest.fixture(scope="module")
def complete_run(tmp_path_factory):
    """A run through the whole pipeline (train, evaluate, report), marked COMPLETE."""
    root = tmp_path_factory.mktemp("trust")
    overrides = [*SMOKE, "eval.units=2", "eval.episodes=1", "eval.steps=10"]
    cfg = compose(overrides)
    run_pipeline(cfg, root / "good", overrides, {}, report=False)
    return cfg, overrides, root


def test_forced_rerun_that_dies_leaves_nothing_stale(complete_run, monkeypatch):
    cfg, overrides, root = complete_run
    run = root / "forced"
    shutil.copytree(root / "good", run)
    assert (run / "results.parquet").exists() and (run / "COMPLETE").exists()

    def die(*args, **kwargs):
        raise RuntimeError("killed while training")

    monkeypatch.setattr("lca.pipeline.train_run", die)
    cfg = OmegaConf.merge(cfg, {"force": True})
    with pytest.raises(RuntimeError, match="killed while training"):
        run_pipeline(cfg, run, overrides, {}, report=False)
    left = {p.name for p in run.iterdir()}
    assert left <= {"config.yaml", "provenance.json", "FAILED", ".lock"}, left
    assert json.loads((run / "FAILED").read_text())["message"] == "killed while training"

    report = build_report([root], root / "report")
    runs = pd.read_csv(root / "report" / "excluded_runs.csv")
    assert runs.status.tolist() == ["failed"] and "killed while training" in runs.reason[0]
    assert "forced" not in (root / "report" / "sim_table.csv").read_text()
    assert "Runs left out" in report.read_text()


def test_report_of_a_folder_without_complete_runs_fails_and_writes_nothing(tmp_path):
    (tmp_path / "empty").mkdir()
    with pytest.raises(FileNotFoundError, match="no complete run"):
        build_report([tmp_path / "empty"], tmp_path / "empty" / "report")
    assert not (tmp_path / "empty" / "report").exists()
    assert list((tmp_path / "empty").iterdir()) == []


@pytest.mark.parametrize(
    ("overrides", "key", "expected"),
    [
        (["difficulty=hard"], "difficulty.stairs_tread", 0.23),
        (["scale=paper"], "terrain.rows", 8),
        (["terrain=stairs_up"], "terrain.mixture.stairs_up", 1.0),
        (["eval.units=3"], "eval.units", 3),
    ],
)
def test_run_config_takes_group_overrides(tmp_path, overrides, key, expected):
    _, run = train_tiny_run(tmp_path / "run", "seed=4")
    cfg = load_run_config(run.path, overrides)
    assert OmegaConf.select(cfg, key) == expected
    assert cfg.seed == 4  # the run's own settings stay


def test_run_config_override_errors_name_the_key(tmp_path):
    _, run = train_tiny_run(tmp_path / "run")
    with pytest.raises(Exception, match="difficulty"):
        load_run_config(run.path, ["difficulty=impossible"])
    with pytest.raises(Exception, match="algo.learning_rate"):
        load_run_config(run.path, ["algo.learning_rate=-1"])


@pytest.mark.parametrize(
    "module",
    [
        ["lca.describe", "scale=smoke", "difficulty=hard"],
        ["lca.scene", "scale=smoke", "terrain=flat", "out={tmp}/s.mjb"],
        [
            "lca.experiment",
            "experiments/paper_sim.yaml",
            "scale=smoke",
            "difficulty=hard",
            "--dry-run",
        ],
    ],
)
def test_compose_entry_points_take_group_overrides(tmp_path, module):
    done = run_module(*[a.replace("{tmp}", str(tmp_path)) for a in module], cwd=REPO)
    assert done.returncode == 0, done.stderr[-2000:]


def test_stage_entry_points_take_group_overrides(tmp_path):
    _, run = train_tiny_run(tmp_path / "run")
    for command in (
        [
            "lca.evaluate",
            f"run_dir={run.path}",
            "difficulty=hard",
            "eval.units=2",
            "eval.episodes=1",
            "eval.steps=5",
        ],
        [
            "lca.hardware",
            f"run_dir={run.path}",
            "scale=smoke",
            "hardware.trials=1",
            "hardware.time_limit_s=0.2",
            "hardware.tasks=[stair_ascent]",
        ],
    ):
        done = run_module(*command, cwd=tmp_path, timeout=300)
        assert done.returncode == 0, done.stderr[-2000:]


def test_a_locked_run_directory_is_refused_by_evaluation(tmp_path):
    _, run = train_tiny_run(tmp_path / "run")
    hold = (
        "import sys, time; from lca.store import RunDir\n"
        "with RunDir(sys.argv[1]).lock():\n    print('locked', flush=True); time.sleep(600)\n"
    )
    holder = subprocess.Popen([sys.executable, "-c", hold, str(run.path)], stdout=subprocess.PIPE)
    try:
        assert holder.stdout.readline().strip() == b"locked"
        done = run_evaluate_cli(run.path, cwd=tmp_path)
        assert done.returncode != 0
        assert f"in use by PID {holder.pid}" in done.stderr
    finally:
        holder.kill()
        holder.wait()
    assert RunDir(run.path).failed is None


def test_unreadable_final_checkpoint_names_the_file_and_the_way_out(tmp_path):
    _, run = train_tiny_run(tmp_path / "run")
    final = next((run.path / "checkpoints").glob("final_*.pt"))
    final.write_bytes(final.read_bytes()[:1000])
    done = run_evaluate_cli(run.path, cwd=tmp_path)
    assert done.returncode != 0
    assert f"cannot read checkpoint {final}" in done.stderr
    assert "force=true" in done.stderr
