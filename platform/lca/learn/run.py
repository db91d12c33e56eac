"""`python run.py`: train one configuration into its run directory, export, evaluate.

A completed run (its COMPLETE marker exists) is skipped unless `force=true`; an interrupted
one resumes from `checkpoints/latest.pt`.
"""

from __future__ import annotations

import json
import logging
import math
import os
import time
from pathlib import Path

from omegaconf import DictConfig

from lca.config.runtime import set_torch_threads
from lca.learn.rundir import RunDir
from lca.learn.trainer import Trainer


def run_training(
    cfg: DictConfig, run_path: Path, overrides: list[str], choices: dict
) -> dict | None:
    run = RunDir(run_path)
    if run.complete and not cfg.force:
        print(f"[lca] skip {run.path} (complete; force=true re-runs it)")
        return None
    if cfg.force:
        run.clear_complete()
        latest = run.latest_checkpoint()
        if latest is not None:
            latest.unlink()
    threads = job_threads(cfg)
    set_torch_threads(threads)
    cfg.sim.num_threads = int(cfg.sim.num_threads) or threads
    os.environ.setdefault("WANDB_RUN_GROUP", run.path.parent.name)
    os.environ.setdefault("WANDB_DIR", str(run.path))
    for noisy in ("onnxscript", "onnx_ir", "torch.onnx"):
        logging.getLogger(noisy).setLevel(logging.WARNING)
    run.path.mkdir(parents=True, exist_ok=True)
    run.write_provenance(cfg, overrides, choices)
    t0 = time.perf_counter()
    trainer = Trainer(cfg, run)
    last = trainer.train()
    exported = trainer.export()
    summary = {
        "iterations": int(cfg.scale.max_iterations),
        "wall_s": round(time.perf_counter() - t0, 1),
        "final": _finite(last),
        "exported": {k: str(v.relative_to(run.path)) for k, v in exported.items()},
        "results": None,  # written by the evaluation stage
    }
    run.mark_complete(json.loads(json.dumps(summary, default=str)))
    print(f"[lca] done {run.path} in {summary['wall_s']} s")
    return summary


def job_threads(cfg: DictConfig) -> int:
    """torch/mjbatch threads for this job: the config's, else what a parallel launcher left
    per job in OMP_NUM_THREADS (joblib: cpu_count // n_jobs), else 0 (library default)."""
    if int(cfg.torch_threads) > 0:
        return int(cfg.torch_threads)
    return int(os.environ.get("OMP_NUM_THREADS", "0") or 0)


def _finite(value):
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {k: _finite(v) for k, v in value.items()}
    return value
