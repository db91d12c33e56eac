"""A static HTML dashboard: tables, figures, the claim, clips and terrains, and every run
with its provenance."""

from __future__ import annotations

import html
import os
import re
from pathlib import Path

import pandas as pd
from jinja2 import Template

from lca.report.collect import RunRecord

PAGE = Template(
    """<!doctype html>
<html lang="en"><head><meta charset="utf-8"><title>lca report</title>
<style>
 body { font-family: system-ui, sans-serif; margin: 2em auto; max-width: 1200px; color: #222; }
 table { border-collapse: collapse; margin: 1em 0; font-size: 0.9em; }
 th, td { border-bottom: 1px solid #ddd; padding: 4px 10px; text-align: center; }
 td.best { font-weight: bold; }
 img { max-width: 100%; }
 code { background: #f4f4f4; padding: 1px 4px; }
 p.note { background: #fde68a; padding: 0.6em 1em; font-weight: bold; }
 figure { display: inline-block; margin: 0 8px 8px 0; vertical-align: top; }
 figcaption { font-size: 0.85em; text-align: center; color: #555; }
 h3 { font-size: 1em; margin: 1em 0 0.4em; }
 figure.terrain img { width: 560px; }
</style></head><body>
<h1>lca: architecture ablations for humanoid locomotion</h1>
{% if note %}<p id="note" class="note">{{ note }}: these runs only check that the pipeline
works; their numbers are not results.</p>{% endif %}
<p>{{ n_runs }} run(s), {{ n_complete }} with evaluation results.</p>
<h2 id="simulation">Simulation results</h2>
<p>{{ sim_caption }}; best per column and difficulty in bold.
Downloads: <a href="sim_table.tex">LaTeX</a>, <a href="sim_table.csv">CSV</a>.</p>
{{ sim_table }}
<h2 id="claim">Two-stage vs one-stage (paired)</h2>
<p>Two-stage minus its one-stage twin (same actor, encoder and seed; units paired by common
random numbers), 95 % paired bootstrap CI. <a href="claim.csv">CSV</a>.</p>
{{ claim_table }}
{{ seeds }}
{{ hardware }}
{{ media }}
<h2 id="training">Training rewards</h2>
<img src="training_rewards.png" alt="training rewards">
<h2 id="runs">Runs</h2>
{{ runs_table }}
{{ excluded }}
</body></html>
"""
)


def runs_table(runs: list[RunRecord], out_dir: Path) -> str:
    rows = []
    for run in runs:
        git = run.provenance.get("git", {})
        rel = os.path.relpath(run.path, out_dir)
        rows.append(
            "<tr>"
            f'<td><a href="{html.escape(rel)}/">{html.escape(run.name)}</a></td>'
            f"<td>{html.escape(run.label)}</td><td>{run.seed}</td>"
            f"<td><code>{html.escape(str(git.get('commit'))[:10])}</code>"
            f"{' (dirty)' if git.get('dirty') else ''}</td>"
            f'<td><a href="{html.escape(rel)}/config.yaml">config</a></td>'
            f"<td>{'yes' if run.episodes is not None else 'no'}</td>"
            "</tr>"
        )
    head = "<tr><th>run</th><th>policy</th><th>seed</th><th>commit</th><th>config</th>"
    return f'<table id="runs-table">{head}<th>results</th></tr>{"".join(rows)}</table>'


def latex_to_text(label: str) -> str:
    for a, b in (
        ("$R_{\\mathrm{succ}}$", "R_succ"),
        ("\\%", "%"),
        ("$\\uparrow$", "↑"),
        ("$\\downarrow$", "↓"),
    ):
        label = label.replace(a, b)
    return label


def sim_table_html(text: pd.DataFrame, best: pd.DataFrame) -> str:
    if text.empty:
        return "<p>No evaluation results yet.</p>"
    plain = text.map(lambda s: s.replace("$\\pm$", "±"))
    plain.columns = pd.MultiIndex.from_tuples([(t, latex_to_text(m)) for t, m in plain.columns])
    classes = best.replace({True: "best", False: ""})
    classes.columns = plain.columns
    styled = plain.style.set_td_classes(classes)
    # Styler names its table T_<uuid>; give it the stable id the page links to
    return re.sub(r'<table id="T_[^"]*"', '<table id="sim-table"', styled.to_html(), count=1)


def hardware_section(table: pd.DataFrame) -> str:
    shown = table.assign(
        success=table.successes.astype(str) + "/" + table.trials.astype(str),
        track_m=table.track_mad_m.map(lambda v: "--" if pd.isna(v) else f"{v:.3f}"),
        mean_abs_drift_m=table.mean_abs_drift_m.round(3),
    )[["policy", "task", "success", "track_m", "mean_abs_drift_m"]]
    return (
        '<h2 id="hardware">Hardware-style tasks (simulation)</h2>\n'
        "<p>Success over trials; Track (m): the mean absolute deviation of the net lateral "
        "drift across the successful trials (the paper's precision), with the mean |drift| "
        'beside it. <a href="hardware_table.tex">LaTeX</a>, '
        '<a href="hardware_table.csv">CSV</a>.</p>\n'
        + shown.to_html(index=False, table_id="hardware-table")
    )


def excluded_section(excluded: pd.DataFrame | None) -> str:
    if excluded is None or excluded.empty:
        return ""
    return (
        '<h2 id="excluded">Runs left out</h2><p>Only complete runs count; these are not '
        '(<a href="excluded_runs.csv">CSV</a>).</p>'
        + excluded.to_html(index=False, table_id="excluded-table", escape=True)
    )


def write_dashboard(
    out_dir: Path,
    runs,
    text,
    best,
    claim: pd.DataFrame,
    hardware: str = "",
    excluded: pd.DataFrame | None = None,
    link_base: Path | None = None,
    note: str = "",
    media: str = "",
    seeds: str = "",
    n_seeds: int = 0,
) -> Path:
    """index.html in `out_dir`; run links are relative to `link_base` (default out_dir), the
    folder the page will finally live in. `media`: the clips and terrains sections (HTML)."""
    claim_html = (
        claim.round(3).to_html(index=False, table_id="claim-table")
        if not claim.empty
        else "<p>No two-stage / one-stage pair with results.</p>"
    )
    page = PAGE.render(
        n_runs=len(runs),
        n_complete=sum(r.episodes is not None for r in runs),
        sim_table=sim_table_html(text, best),
        claim_table=claim_html,
        runs_table=runs_table(runs, Path(link_base or out_dir)),
        hardware=hardware,
        excluded=excluded_section(excluded),
        note=note,
        media=media,
        seeds=seeds,
        sim_caption=(
            "IQM across training seeds [95 % stratified bootstrap CI, units resampled within each "
            "seed]"
            if n_seeds >= 2
            else "Mean ± standard deviation across units (all seeds pooled)"
        ),
    )
    path = out_dir / "index.html"
    path.write_text(page)
    return path


def seeds_section(seeds: pd.DataFrame, improvement: pd.DataFrame, n_seeds: int, out_dir) -> str:
    """Training seeds: per-seed values, mean and IQM across seeds with stratified bootstrap
    CIs, the probability of improvement, and the seed and performance-profile figures. With
    one seed it says so and claims nothing across seeds."""
    most = int(seeds["n_seeds"].max()) if not seeds.empty else 0
    if n_seeds < 2 <= most:
        head = (
            f"<p>Between 1 and {most} training seeds per row (<code>n_seeds</code>): each seed's "
            "mean over units, with the mean and IQM across seeds and their 95 % stratified "
            "bootstrap CIs where a row has two or more. The tables pool each row's seeds' "
            'units. <a href="seed_table.csv">CSV</a>.</p>'
        )
    elif n_seeds < 2:
        head = (
            "<p>One training seed per policy (at least one row): the tables show the spread "
            "across units; no confidence interval across seeds can be computed. Declare "
            "<code>seed=0,1,2</code> (or an experiment's <code>seeds:</code>) for one.</p>"
        )
    else:
        head = (
            f"<p>At least {n_seeds} training seeds per row: each seed's mean over units, their "
            "mean and interquartile mean (IQM) with 95 % stratified bootstrap CIs (units "
            'resampled within each seed). <a href="seed_table.csv">CSV</a>.</p>'
        )
    table = seeds.round(3).to_html(index=False, table_id="seed-table")
    figures = "".join(
        f'<figure><img src="{p.name}" alt="{html.escape(p.stem)}"></figure>'
        for p in sorted(Path(out_dir).glob("seeds_*.png"))
    )
    pairs = (
        "<p>Two-stage against one-stage over the seeds both have: each seed's difference of "
        "means (better = more success, fewer contacts), whether its sign agrees across seeds, "
        "and P(two-stage better) over units, averaged over seeds, with its stratified CI. "
        '<a href="improvement.csv">CSV</a>.</p>'
        + improvement.round(3).to_html(index=False, table_id="improvement-table")
        if not improvement.empty
        else ""
    )
    return (
        '<h2 id="seeds">Training seeds</h2>\n'
        + head
        + table
        + pairs
        + figures
        + '<h3>Performance profiles</h3><img src="performance_profiles.png" '
        'alt="performance profiles">'
    )
