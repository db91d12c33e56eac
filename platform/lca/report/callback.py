"""Hydra callback: build the report of a sweep when the multirun ends."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from hydra.experimental.callback import Callback
from omegaconf import DictConfig


class ReportCallback(Callback):
    def on_multirun_end(self, config: DictConfig, **kwargs: Any) -> None:
        from lca.report.build import build_report
        from lca.store import FAILED

        sweep_dir = Path(config.hydra.sweep.dir)
        try:
            index = build_report([sweep_dir], sweep_dir / "report")
            print(f"[lca] sweep report: {index}")
        except FileNotFoundError as err:
            print(f"[lca] no sweep report: {err}")
        failed = sorted(p.parent.name for p in sweep_dir.glob(f"*/{FAILED}"))
        if failed:  # reported above; the sweep as a whole did not succeed
            raise SystemExit(f"[lca] {len(failed)} run(s) of the sweep failed: {failed}")
