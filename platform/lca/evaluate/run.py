"""Evaluate one run directory and write its results files."""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from lca.evaluate.metrics import summarize
from lca.evaluate.policy import load_run_config
from lca.evaluate.protocol import evaluate_run
from lca.learn.rundir import atomic_write


def evaluate_and_write(
    run_dir: Path, overrides: list[str] | None = None, log=print
) -> pd.DataFrame:
    cfg = load_run_config(run_dir, overrides)
    episodes = evaluate_run(run_dir, cfg, log=log)
    episodes.insert(0, "run", Path(run_dir).name)
    tmp = Path(run_dir) / ".results.parquet.tmp"
    episodes.to_parquet(tmp, index=False)
    tmp.replace(Path(run_dir) / "results.parquet")
    ev = cfg.eval
    summary = summarize(episodes, ev.bootstrap_resamples, ev.confidence, ev.seed)
    atomic_write(Path(run_dir) / "summary.csv", summary.to_csv(index=False))
    return summary
