"""One run end to end: train -> evaluate -> report, each stage reading the run directory.

A completed run (its COMPLETE marker exists) is skipped unless `force=true`; an interrupted
one resumes where it stopped: training from `checkpoints/latest.pt`, evaluation at its first
missing episode round.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

from omegaconf import DictConfig

from lca.evaluate.run import evaluate_and_write
from lca.learn.run import train_run
from lca.learn.rundir import RunDir
from lca.report.build import build_report


def run_pipeline(
    cfg: DictConfig, run_path: Path, overrides: list[str], choices: dict, report: bool = True
) -> dict | None:
    run = RunDir(run_path)
    if run.complete and not cfg.force:
        print(f"[lca] skip {run.path} (complete; force=true re-runs it)")
        return None
    if cfg.force:
        run.clear_complete()
        for stale in (run.checkpoints, run.path / "eval"):
            shutil.rmtree(stale, ignore_errors=True)
    run.path.mkdir(parents=True, exist_ok=True)
    run.write_provenance(cfg, overrides, choices)
    summary = train_run(cfg, run)
    evaluate_and_write(run.path)
    summary["results"] = {"episodes": "results.parquet", "summary": "summary.csv"}
    if report:
        summary["report"] = str(build_report([run.path], run.path / "report").relative_to(run.path))
    run.mark_complete(json.loads(json.dumps(summary, default=str)))
    print(f"[lca] done {run.path}")
    return summary
