"""Build the whole report for a set of run directories."""

from __future__ import annotations

import os
import shutil
import tempfile
from pathlib import Path

import pandas as pd

from lca.report.collect import POOLED, find_run_dirs, load_run, run_status
from lca.report.dashboard import hardware_section, seeds_section, write_dashboard
from lca.report.figures import plot_rewards
from lca.report.hardware_table import hardware_table
from lca.report.media import clips_section, terrains_section
from lca.report.seed_figures import profile_figure, seed_figures
from lca.report.seeds import improvement_table, seed_table
from lca.report.tables import (
    across_seed_count,
    best_mask,
    claim_table,
    long_table,
    pooled_episodes,
    to_latex,
    wide_table,
)


def build_report(paths: list[Path], out_dir: Path) -> Path:
    """Tables (LaTeX, CSV), the training figure (PNG, PDF), the runs' clips and terrain
    previews (`media/`) and index.html into `out_dir`.

    Only complete runs count; the others are listed apart with their status. The report is
    built in a temporary folder and then swapped in, so an interrupted build never leaves a
    half-written report."""
    out_dir = Path(out_dir)
    found = find_run_dirs(paths)
    status = {p: run_status(p) for p in found}
    complete = [p for p in found if status[p][0] == "complete"]
    if not complete:
        listed = "; ".join(f"{p} ({status[p][0]})" for p in found) or "none"
        raise FileNotFoundError(
            f"no complete run directories under {[str(p) for p in paths]} (found: {listed})"
        )
    excluded = pd.DataFrame(
        [
            {"run": str(p), "status": status[p][0], "reason": status[p][1]}
            for p in found
            if p not in complete
        ],
        columns=["run", "status", "reason"],
    )
    out_dir.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(dir=out_dir.parent, prefix=f".{out_dir.name}."))
    try:
        _build(complete, excluded, tmp, out_dir)
        old = None
        if out_dir.exists():
            old = Path(tempfile.mkdtemp(dir=out_dir.parent, prefix=f".{out_dir.name}.old."))
            os.replace(out_dir, old / "report")
        os.replace(tmp, out_dir)
        if old is not None:
            shutil.rmtree(old, ignore_errors=True)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return out_dir / "index.html"


SMOKE_NOTE = "smoke scale - not results"  # scale=smoke runs only check that things run


def _mark(frame: pd.DataFrame, note: str) -> pd.DataFrame:
    return frame.assign(note=note) if note else frame


def _build(run_dirs: list[Path], excluded: pd.DataFrame, out_dir: Path, final: Path) -> None:
    runs = [load_run(p) for p in run_dirs]
    note = SMOKE_NOTE if any(r.scale == "smoke" for r in runs) else ""
    episodes = pooled_episodes(runs)
    table = long_table(episodes) if not episodes.empty else episodes
    _mark(table, note).to_csv(out_dir / "sim_table.csv", index=False)
    seeds = seed_table(episodes) if not episodes.empty else pd.DataFrame()
    _mark(seeds, note).to_csv(out_dir / "seed_table.csv", index=False)
    n_seeds = across_seed_count(seeds)
    if table.empty:
        text = best = table
    else:
        text, means = wide_table(table, seeds)
        best = best_mask(means)
        notes = [f"\\textbf{{{note.replace(' - ', ' --- ')}.}}"] if note else []
        if any(r.label.endswith(POOLED) for r in runs):
            notes.append(
                "CNN (pooled): $2\\times2$ max-pooling after each convolution "
                "(\\texttt{encoder.pool}), not the paper's CNN."
            )
        (out_dir / "sim_table.tex").write_text(to_latex(text, best, " ".join(notes), n_seeds))
    claim = claim_table(runs)
    _mark(claim, note).to_csv(out_dir / "claim.csv", index=False)
    improvement = improvement_table(runs)
    _mark(improvement, note).to_csv(out_dir / "improvement.csv", index=False)
    if not episodes.empty:
        if seeds["n_seeds"].max() >= 2:  # one seed per row: single points, nothing to show
            seed_figures(seeds, out_dir)
        profile_figure(episodes, out_dir / "performance_profiles.png")
    excluded.to_csv(out_dir / "excluded_runs.csv", index=False)
    plot_rewards(runs, out_dir / "training_rewards")
    hardware_html = ""
    trials = {}
    for run in runs:
        if run.hardware is not None:
            trials[run.label] = pd.concat([trials.get(run.label), run.hardware])
    if trials:
        hw_table, hw_latex = hardware_table(trials)
        _mark(hw_table, note).to_csv(out_dir / "hardware_table.csv", index=False)
        (out_dir / "hardware_table.tex").write_text(hw_latex)
        hardware_html = hardware_section(hw_table)
    media = clips_section(runs, out_dir) + "\n" + terrains_section(runs, out_dir)
    write_dashboard(
        out_dir,
        runs,
        text,
        best,
        claim,
        hardware_html,
        excluded,
        link_base=final,
        note=note,
        media=media,
        seeds=seeds_section(seeds, improvement, n_seeds, out_dir) if not episodes.empty else "",
        n_seeds=n_seeds,
    )
