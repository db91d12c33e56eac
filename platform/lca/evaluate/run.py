"""Evaluate one run directory and write its results files, then its clips and previews."""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from lca.evaluate.media import make_media
from lca.evaluate.metrics import summarize
from lca.evaluate.policy import load_run_config
from lca.evaluate.protocol import evaluate_run
from lca.store import RunDir, atomic_write, write_atomically


def evaluate_and_write(
    run_dir: Path, overrides: list[str] | None = None, log=print
) -> pd.DataFrame:
    cfg = load_run_config(run_dir, overrides)
    with RunDir(run_dir).lock():
        episodes = evaluate_run(run_dir, cfg, log=log)
        episodes.insert(0, "run", Path(run_dir).name)
        write_atomically(
            Path(run_dir) / "results.parquet", lambda tmp: episodes.to_parquet(tmp, index=False)
        )
        ev = cfg.eval
        summary = summarize(episodes, ev.bootstrap_resamples, ev.confidence, ev.seed)
        atomic_write(Path(run_dir) / "summary.csv", summary.to_csv(index=False))
        make_media(run_dir, cfg, log)  # clips and terrain previews (eval.videos)
    return summary
