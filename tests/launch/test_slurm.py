"""`hydra/launcher=slurm` for real: sweeps submitted with sbatch (through submitit) to the
one-node cluster of scripts/slurm_local.sh, which .ci/run starts. Skips, saying why, where no
cluster answers."""

from __future__ import annotations

import json
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import pytest
from _cli import REPO, cli_env

pytestmark = [pytest.mark.slow, pytest.mark.e2e]

# a job fits the 2-core machine: one CPU, 2 GB, minutes
JOBS = [
    "hydra/launcher=slurm",
    "hydra.launcher.cpus_per_task=1",
    "hydra.launcher.mem_gb=2",
    "hydra.launcher.timeout_min=20",
    "scale=smoke",
    "logger=none",
    "torch_threads=1",
    "sim.num_threads=1",
    "eval.units=2",
    "eval.episodes=1",
    "eval.steps=10",
]


@pytest.fixture(scope="module", autouse=True)
def cluster() -> None:
    if shutil.which("sinfo") is None:
        pytest.skip("no SLURM here (sinfo is not on PATH): bash scripts/slurm_local.sh start")
    out = subprocess.run(["sinfo", "-h", "-o", "%T"], capture_output=True, text=True, check=False)
    states = set(out.stdout.split())
    if out.returncode != 0 or not states & {"idle", "mixed", "allocated"}:
        found = out.stdout.strip() or out.stderr.strip()
        pytest.skip(f"no SLURM node takes jobs ({found}): bash scripts/slurm_local.sh start")


def sweep(runs_root: Path, *args: str, wait: bool = True) -> subprocess.Popen:
    process = subprocess.Popen(
        [sys.executable, str(REPO / "run.py"), "-m", *JOBS, *args, f"runs_root={runs_root}"],
        cwd=runs_root.parent,
        env=cli_env(),
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )
    if wait:
        process.wait(timeout=900)
    return process


def job_states() -> dict[str, str]:
    """Job (`<array job>_<task>` for a sweep's array, else its id) -> its final state, from
    the cluster's job-completion log."""
    config = subprocess.run(["scontrol", "show", "config"], capture_output=True, text=True)
    path = re.search(r"JobCompLoc\s*=\s*(\S+)", config.stdout).group(1)
    states = {}
    for line in Path(path).read_text().splitlines():
        fields = dict(re.findall(r"(\w+)=(\S*)", line))
        array = fields.get("ArrayJobId")
        name = f"{array}_{fields['ArrayTaskId']}" if array else fields["JobId"]
        states[name] = fields["JobState"]
    return states


def run_dirs(runs_root: Path) -> list[Path]:
    return sorted(p for p in runs_root.iterdir() if (p / "config.yaml").exists())


def jobs_of(run: Path) -> list[str]:
    """The SLURM jobs that ran this run (one per try): its linked logs' names."""
    names = [p.name.removeprefix("slurm-").removesuffix(".out") for p in run.glob("slurm-*.out")]
    return sorted(names, key=lambda job: tuple(int(part) for part in job.split("_")))


def test_four_run_sweep_through_sbatch(tmp_path: Path) -> None:
    runs_root = tmp_path / "runs"
    process = sweep(runs_root, "actor=mlp,lstm", "curriculum=one,two")
    output = process.stdout.read()
    assert process.returncode == 0, output[-3000:]
    runs = run_dirs(runs_root)
    assert len(runs) == 4, runs
    states = job_states()
    for run in runs:
        assert (run / "COMPLETE").is_file() and (run / "results.parquet").is_file(), run
        jobs = jobs_of(run)
        assert len(jobs) == 1 and states[jobs[0]] == "COMPLETED", (run, jobs)
        log = (run / f"slurm-{jobs[0]}.out").read_text()
        assert f"[lca] done {run}" in log  # the job's own stdout, in its run directory
    assert output.count("[lca] sweep report:") == 1  # built once, when every job has ended
    table = pd.read_csv(runs_root / "report" / "sim_table.csv")
    assert table["policy"].nunique() == 4
    # submitted again: every run is complete, so every job skips it
    again = sweep(runs_root, "actor=mlp,lstm", "curriculum=one,two")
    assert again.returncode == 0
    for run in run_dirs(runs_root):
        second = jobs_of(run)[-1]
        assert "[lca] skip" in (run / f"slurm-{second}.out").read_text()


def test_requeued_job_resumes_from_its_checkpoint(tmp_path: Path) -> None:
    runs_root = tmp_path / "runs"
    iterations = 400  # long enough to be killed mid-training (KillWait: 5 s)
    process = sweep(runs_root, "policy=blind", f"scale.max_iterations={iterations}", wait=False)
    deadline = time.monotonic() + 600
    run = None
    while time.monotonic() < deadline:
        found = run_dirs(runs_root) if runs_root.exists() else []
        curve = found[0] / "train_curve.csv" if found else None
        if curve is not None and curve.exists() and len(curve.read_text().splitlines()) > 10:
            run = found[0]
            break
        time.sleep(0.5)
    assert run is not None, "the job never got going"
    job = jobs_of(run)[0]
    subprocess.run(["scontrol", "requeue", job], check=True)
    # a requeued job waits two minutes before it may start again: let it start now
    for _ in range(60):
        if (
            "PENDING"
            in subprocess.run(
                ["scontrol", "show", "job", job], capture_output=True, text=True
            ).stdout
        ):
            break
        time.sleep(1)
    subprocess.run(["scontrol", "update", f"jobid={job}", "starttime=now"], check=True)
    process.wait(timeout=900)
    assert process.returncode == 0, process.stdout.read()[-3000:]
    assert (run / "COMPLETE").is_file()
    curve = pd.read_csv(run / "train_curve.csv")
    assert curve["iteration"].tolist() == list(range(iterations))  # no gap, no repeat
    log = (run / f"slurm-{job}.out").read_text()
    assert "[lca] resuming" in log, log[-2000:]


def test_a_failing_job_is_reported_and_loses_no_other(tmp_path: Path) -> None:
    runs_root = tmp_path / "runs"
    # the second run's warm start names no checkpoint: it fails once it starts training
    process = sweep(runs_root, "policy=blind", "algo.init_from='',missing.pt")
    output = process.stdout.read()
    assert process.returncode != 0 and "1 run(s) of the sweep failed" in output, output[-3000:]
    runs = run_dirs(runs_root)
    assert len(runs) == 2, output[-3000:]
    failed = [r for r in runs if (r / "FAILED").exists()]
    complete = [r for r in runs if (r / "COMPLETE").exists()]
    assert len(failed) == 1 and len(complete) == 1, output[-3000:]
    reason = json.loads((failed[0] / "FAILED").read_text())
    assert "checkpoint" in json.dumps(reason)
    left_out = pd.read_csv(runs_root / "report" / "excluded_runs.csv")
    assert left_out["status"].tolist() == ["failed"]
    assert "Runs left out" in (runs_root / "report" / "index.html").read_text()
