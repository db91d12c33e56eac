"""Train one configuration into its run directory and export the final policy."""

from __future__ import annotations

import csv
import logging
import math
import os
import time
from pathlib import Path

from omegaconf import DictConfig

from lca.config.runtime import set_torch_threads
from lca.learn.trainer import Trainer
from lca.learn.variants import actor_spec
from lca.store import RunDir


def job_threads(cfg: DictConfig) -> int:
    """torch/mjbatch threads for this job: the config's, else what a parallel launcher left
    per job in OMP_NUM_THREADS (joblib: cpu_count // n_jobs), else 0 (library default)."""
    if int(cfg.torch_threads) > 0:
        return int(cfg.torch_threads)
    return int(os.environ.get("OMP_NUM_THREADS", "0") or 0)


def finite(value):
    """NaN/inf -> None, recursively, so summaries are valid JSON."""
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {k: finite(v) for k, v in value.items()}
    return value


def curve_totals(curve: Path) -> dict:
    """Falls and non-finite resets summed over the run (from its train_curve.csv)."""
    totals = {"falls_total": 0, "nonfinite_total": 0, "nonfinite_actions_total": 0}
    with open(curve, newline="") as f:
        for row in csv.DictReader(f):
            for key in totals:
                value = row.get(key.removesuffix("_total"), "")
                totals[key] += int(float(value)) if value not in ("", None) else 0
    return totals


def train_run(cfg: DictConfig, run: RunDir) -> dict:
    threads = job_threads(cfg)
    set_torch_threads(threads)
    cfg.sim.num_threads = int(cfg.sim.num_threads) or threads
    # each run its own wandb folder; the runs of one sweep share a group
    os.environ["WANDB_RUN_GROUP"] = run.path.parent.name
    os.environ["WANDB_DIR"] = str(run.path)
    for noisy in ("onnxscript", "onnx_ir", "torch.onnx"):
        logging.getLogger(noisy).setLevel(logging.WARNING)
    if not actor_spec(cfg.actor.kind).exports:
        print(f"[lca] actor kind '{cfg.actor.kind}' declares no export: exported/ is skipped")
    t0 = time.perf_counter()
    trainer = Trainer(cfg, run)
    last = trainer.train()
    exported = trainer.export()
    counters = curve_totals(run.curve)
    return {
        "iterations": int(cfg.scale.max_iterations),
        **counters,
        "train_wall_s": round(time.perf_counter() - t0, 1),
        "final": finite(last),
        "exported": {k: str(v.relative_to(run.path)) for k, v in exported.items()},
    }
