"""One run end to end: train -> evaluate -> report, each stage reading the run directory.

A completed run (its COMPLETE marker exists) is skipped unless `force=true`; an interrupted
one resumes where it stopped: training from `checkpoints/latest.pt`, evaluation at its first
missing episode round.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

from omegaconf import DictConfig

from lca.evaluate.run import evaluate_and_write
from lca.learn.run import train_run
from lca.report.build import build_report
from lca.report.reference import reference_runs
from lca.store import FAILED, RunDir


def run_pipeline(
    cfg: DictConfig, run_path: Path, overrides: list[str], choices: dict, report: bool = True
) -> dict | None:
    run = RunDir(run_path)
    with run.lock():  # a second process on this run fails here, naming the owner
        link_job_logs(run.path)  # a cluster job's log, even when it only skips the run
        if run.complete and not cfg.force:
            print(f"[lca] skip {run.path} (complete; force=true re-runs it)")
            return None
        if cfg.force:
            run.clear_outputs()
        (run.path / FAILED).unlink(missing_ok=True)
        run.path.mkdir(parents=True, exist_ok=True)
        run.write_provenance(cfg, overrides, choices)
        try:
            summary = train_run(cfg, run)
            evaluate_and_write(run.path)
        except Exception as error:
            run.mark_failed(error)
            raise
        summary["results"] = {"episodes": "results.parquet", "summary": "summary.csv"}
        run.mark_complete(json.loads(json.dumps(summary, default=str)))  # results are final
        if report:  # a view of the complete run; rebuilt any time with `python -m lca.report`
            # shipped policies evaluated on the same cells, so a first table has signal
            index = build_report([run.path, *reference_runs(cfg)], run.path / "report")
            summary["report"] = str(index.relative_to(run.path))
            run.mark_complete(json.loads(json.dumps(summary, default=str)))
    print(f"[lca] done {run.path}")
    return summary


def link_job_logs(run_dir: Path) -> None:
    """Under SLURM (the submitit launcher), link the job's stdout and stderr into the run
    directory as `slurm-<job id>.out` / `.err`: one pair per try of a requeued job."""
    if "SLURM_JOB_ID" not in os.environ or "SUBMITIT_FOLDER" not in os.environ:
        return
    import submitit

    job = submitit.JobEnvironment()
    Path(run_dir).mkdir(parents=True, exist_ok=True)
    for source, suffix in ((job.paths.stdout, "out"), (job.paths.stderr, "err")):
        link = Path(run_dir) / f"slurm-{job.job_id}.{suffix}"
        if not link.is_symlink():
            link.symlink_to(Path(source).resolve())
