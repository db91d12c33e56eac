"""Build the whole report for a set of run directories."""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from lca.report.collect import find_run_dirs, load_run
from lca.report.dashboard import hardware_section, write_dashboard
from lca.report.figures import plot_rewards
from lca.report.hardware_table import hardware_table
from lca.report.tables import (
    best_mask,
    claim_table,
    long_table,
    pooled_episodes,
    to_latex,
    wide_table,
)


def build_report(paths: list[Path], out_dir: Path) -> Path:
    """Tables (LaTeX, CSV), the training figure (PNG, PDF) and index.html into `out_dir`."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    runs = [load_run(p) for p in find_run_dirs(paths)]
    if not runs:
        raise FileNotFoundError(f"no run directories under {[str(p) for p in paths]}")
    episodes = pooled_episodes(runs)
    table = long_table(episodes) if not episodes.empty else episodes
    table.to_csv(out_dir / "sim_table.csv", index=False)
    if table.empty:
        text = best = table
    else:
        text, means = wide_table(table)
        best = best_mask(means)
        (out_dir / "sim_table.tex").write_text(to_latex(text, best))
    claim = claim_table(runs)
    claim.to_csv(out_dir / "claim.csv", index=False)
    plot_rewards(runs, out_dir / "training_rewards")
    hardware_html = ""
    trials = {}
    for run in runs:
        if run.hardware is not None:
            trials[run.label] = pd.concat([trials.get(run.label), run.hardware])
    if trials:
        hw_table, hw_latex = hardware_table(trials)
        hw_table.to_csv(out_dir / "hardware_table.csv", index=False)
        (out_dir / "hardware_table.tex").write_text(hw_latex)
        hardware_html = hardware_section(hw_table)
    return write_dashboard(out_dir, runs, text, best, claim, hardware_html)
