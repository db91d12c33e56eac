"""`python run.py` as a user runs it: sweeps with the basic and the joblib launcher, skipping
completed runs, resuming a killed run, a bad override, and what a run records about itself."""

from __future__ import annotations

import json
import re
import subprocess
from importlib import metadata
from pathlib import Path

import pytest
import torch
from omegaconf import OmegaConf

from lca.config import compose
from lca.store import PACKAGES
from lca.testhook import KILLED

from .helpers import (
    REPO,
    SWEEP_ARGS,
    cli_command,
    cli_env,
    complete_runs,
    read_curve,
    run_cli,
)

pytestmark = [pytest.mark.slow, pytest.mark.e2e]  # run.py end to end: see README

RUN_NAMES = ["actor=lstm,logger=none,scale=smoke", "actor=mlp,logger=none,scale=smoke"]


def _sweep_args(launcher: str, runs_root: Path) -> list[str]:
    args = [*SWEEP_ARGS, f"runs_root={runs_root}"]
    return args if launcher == "basic" else [*args, f"hydra/launcher={launcher}"]


@pytest.fixture(scope="module", params=["basic", "local"])
def sweep(request, tmp_path_factory) -> dict:
    """`python run.py -m actor=mlp,lstm scale=smoke runs_root=<tmp> logger=none torch_threads=1`
    with the default (basic) launcher and with `hydra/launcher=local` (joblib, 2 workers)."""
    launcher = request.param
    root = tmp_path_factory.mktemp(f"sweep_{launcher}")
    runs_root = root / "runs"
    out = run_cli(*_sweep_args(launcher, runs_root), cwd=root, timeout=240)
    return {"launcher": launcher, "cwd": root, "runs_root": runs_root, "result": out}


def test_sweep_completes_then_skips(sweep) -> None:
    first = sweep["result"]
    assert first.returncode == 0, first.stdout + first.stderr
    runs_root: Path = sweep["runs_root"]
    runs = complete_runs(runs_root)
    assert [p.name for p in runs] == RUN_NAMES
    assert first.stdout.count("[lca] done") == 2
    for run in runs:
        marker = json.loads((run / "COMPLETE").read_text())
        assert marker["iterations"] == 2 and marker["final"]["iteration"] == 1
        assert [int(r["iteration"]) for r in read_curve(run / "train_curve.csv")] == [0, 1]
        assert (run / "checkpoints" / "latest.pt").is_file()
    before = {
        run: ((run / "COMPLETE").stat().st_mtime_ns, (run / "COMPLETE").read_bytes())
        for run in runs
    }

    again = run_cli(*_sweep_args(sweep["launcher"], runs_root), cwd=sweep["cwd"], timeout=240)
    assert again.returncode == 0, again.stdout + again.stderr
    assert again.stdout.count("[lca] skip") == 2, again.stdout
    assert "[lca] it" not in again.stdout and "[lca] done" not in again.stdout
    for run, (mtime, content) in before.items():
        assert (run / "COMPLETE").stat().st_mtime_ns == mtime
        assert (run / "COMPLETE").read_bytes() == content
    assert complete_runs(runs_root) == runs


def test_provenance_and_config(sweep) -> None:
    runs_root: Path = sweep["runs_root"]
    for actor in ("mlp", "lstm"):
        run = runs_root / f"actor={actor},logger=none,scale=smoke"
        prov = json.loads((run / "provenance.json").read_text())
        overrides = [
            f"actor={actor}",
            "scale=smoke",
            "logger=none",
            "torch_threads=1",
            f"runs_root={runs_root}",
        ]
        assert prov["overrides"] == overrides
        choices = prov["choices"]
        expected = {
            "actor": actor,
            "encoder": "cnn",
            "curriculum": "two",
            "scale": "smoke",
            "logger": "none",
            "terrain": "mixed",
            "robot": "g1",
            "hydra/launcher": sweep["launcher"],
        }
        assert {k: choices.get(k) for k in expected} == expected
        assert prov["seed"] == 0

        git = prov["git"]
        assert re.fullmatch(r"[0-9a-f]{40}", git["commit"]), git
        kind = subprocess.run(
            ["git", "cat-file", "-t", git["commit"]],
            cwd=REPO,
            capture_output=True,
            text=True,
            check=False,
        ).stdout.strip()
        assert kind == "commit"
        assert isinstance(git["dirty"], bool)

        assert set(prov["versions"]) == set(PACKAGES)
        for name in PACKAGES:
            assert prov["versions"][name] == metadata.version(name), name

        text = (run / "config.yaml").read_text()
        assert "${" not in text  # written resolved
        saved = OmegaConf.to_container(OmegaConf.load(run / "config.yaml"), resolve=True)
        assert saved == OmegaConf.to_container(compose(overrides), resolve=True)
        assert saved["seed"] == prov["seed"]


# ---- kill and resume -----------------------------------------------------------------------

RESUME_ARGS = (
    "scale=smoke",
    "scale.max_iterations=6",
    "scale.checkpoint_interval=2",
    "logger=none",
    "torch_threads=1",
)
RESUME_RUN = "logger=none,scale.checkpoint_interval=2,scale.max_iterations=6,scale=smoke"


def test_killed_run_resumes(tmp_path) -> None:
    """Kill a 6-iteration run once its first `latest.pt` (iteration 1) exists and the curve
    has a row past it; re-running the same command resumes from the checkpoint, redoes only
    the lost iterations and completes with each iteration once in train_curve.csv."""
    runs_root = tmp_path / "runs"
    args = [*RESUME_ARGS, f"runs_root={runs_root}"]
    run = runs_root / RESUME_RUN
    latest, curve = run / "checkpoints" / "latest.pt", run / "train_curve.csv"
    # the test hook ends the run like a SIGKILL right after iteration 2: the checkpoint is
    # iteration 1's (every 2 iterations) and the curve holds a row past it
    killed = subprocess.run(
        cli_command(*args),
        cwd=tmp_path,
        env=cli_env() | {"LCA_TEST_EXIT_AFTER": "iteration:2"},
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    first_out = killed.stdout + killed.stderr
    assert killed.returncode == KILLED, first_out[-3000:]
    assert not (run / "COMPLETE").exists(), first_out
    ckpt_iter = torch.load(latest, weights_only=False, map_location="cpu")["iter"]
    assert ckpt_iter == 1
    assert len(read_curve(curve)) == 3  # iterations 0, 1, 2
    rows_before = read_curve(curve)
    kept = [r for r in rows_before if int(r["iteration"]) <= ckpt_iter]

    second = run_cli(*args, cwd=tmp_path)
    assert second.returncode == 0, second.stdout + second.stderr
    assert f"resuming {RESUME_RUN} at iteration {ckpt_iter + 1}/6" in second.stdout
    assert "[lca] it     1/6" not in second.stdout  # iteration 0 not redone
    assert f"[lca] it {ckpt_iter + 2:>5}/6" in second.stdout
    assert (run / "COMPLETE").is_file()
    marker = json.loads((run / "COMPLETE").read_text())
    assert marker["final"]["iteration"] == 5
    # provenance keeps the killed start and says how this one resumed
    provenance = json.loads((run / "provenance.json").read_text())
    assert provenance["resumed"] == {"iteration": ckpt_iter + 1, "from": "latest.pt", "exact": True}
    [killed_start] = provenance["earlier_starts"]
    assert "resumed" not in killed_start and killed_start["started"] <= provenance["started"]
    assert killed_start["cpu"] == provenance["cpu"]
    rows = read_curve(curve)
    assert [int(r["iteration"]) for r in rows] == list(range(6))
    assert rows[: len(kept)] == kept  # rows up to the checkpoint kept as they were
    assert torch.load(latest, weights_only=False, map_location="cpu")["iter"] == 5


# ---- bad override --------------------------------------------------------------------------


@pytest.mark.parametrize("grid", [("actor=gru",), ("-m", "actor=mlp,gru")], ids=["run", "sweep"])
def test_unknown_actor_fails_listing_options(grid, tmp_path) -> None:
    runs_root = tmp_path / "runs"
    out = run_cli(
        *grid,
        "scale=smoke",
        "logger=none",
        "torch_threads=1",
        f"runs_root={runs_root}",
        cwd=tmp_path,
    )
    text = out.stdout + out.stderr
    assert out.returncode != 0
    assert "Could not find 'actor/gru'" in text
    options = text.split("Available options in 'actor':", 1)[1].split()[:2]
    assert sorted(options) == ["lstm", "mlp"]
    assert complete_runs(runs_root) == []
    assert not list(tmp_path.rglob("*.pt"))


def test_two_processes_on_one_run_one_owner(tmp_path) -> None:
    """Two identical `python run.py` started together: one trains the run to COMPLETE with
    its whole curve, the other stops at once naming the owner."""
    args = [
        "scale=smoke",
        "logger=none",
        "torch_threads=1",
        "scale.max_iterations=6",
        "eval.units=2",
        "eval.episodes=1",
        "eval.steps=5",
        f"runs_root={tmp_path}",
    ]
    procs = [
        subprocess.Popen(
            cli_command(*args),
            cwd=tmp_path,
            env=cli_env(),
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        for _ in range(2)
    ]
    outs = [p.communicate(timeout=300) for p in procs]
    codes = sorted(p.returncode for p in procs)
    assert codes[0] == 0 and codes[1] != 0, outs
    loser = next(err for p, (_, err) in zip(procs, outs, strict=True) if p.returncode != 0)
    assert "is in use by PID" in loser
    runs = complete_runs(tmp_path)
    assert len(runs) == 1
    rows = read_curve(runs[0] / "train_curve.csv")
    assert [int(r["iteration"]) for r in rows] == list(range(6))
