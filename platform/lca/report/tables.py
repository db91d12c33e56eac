"""The paper's simulation table (LaTeX + CSV) and the two-stage vs one-stage claim."""

from __future__ import annotations

import numpy as np
import pandas as pd

from lca.evaluate.metrics import (
    CELL_KEYS,
    METRICS,
    paired_difference,
    summarize,
    unit_values,
)
from lca.evaluate.terrains import eval_label, eval_terrains
from lca.report.collect import RunRecord, row_key

DIFFICULTY_ORDER = ["medium", "hard"]  # the paper's blocks; other difficulties follow, sorted
LOWER_IS_BETTER = {"contacts_per_step", "track_cm_s"}
RESAMPLES, CONFIDENCE, SEED = 2000, 0.95, 0
CLAIM_COLUMNS = [
    "two_stage",
    "one_stage",
    "seed",
    "terrain",
    "difficulty",
    "metric",
    "diff",
    "ci_low",
    "ci_high",
    "n_units",
]


def pooled_episodes(runs: list[RunRecord]) -> pd.DataFrame:
    """All episodes of runs with results; units made unique across seeds."""
    frames = []
    for run in runs:
        if run.episodes is None:
            continue
        frame = run.episodes.copy()
        frame["policy"] = run.label
        frame["seed"] = run.seed
        frame["unit"] = frame["unit"].astype(str).radd(f"{run.seed}:")
        frames.append(frame)
    return pd.concat(frames, ignore_index=True) if frames else pd.DataFrame()


def long_table(episodes: pd.DataFrame) -> pd.DataFrame:
    """One row per policy x cell x metric: mean, se, CI over all units of all seeds."""
    keys = ["policy", *CELL_KEYS]
    table = summarize(episodes, RESAMPLES, CONFIDENCE, SEED, by=keys)
    if table.empty:
        return table
    seeds = episodes.groupby(keys)["seed"].nunique()
    table.insert(4, "n_seeds", [seeds[k] for k in table[keys].itertuples(index=False)])
    table = table.drop(columns="n_episodes").rename(
        columns={"cell_terrain": "terrain", "cell_difficulty": "difficulty"}
    )
    order = table["policy"].map(row_key)
    return table.assign(_o=order).sort_values(["_o", "difficulty", "terrain"]).drop(columns="_o")


def _cell_text(mean: float, sd: float, metric: str) -> str:
    return f"{mean:.2f}" if metric == "success" else f"{mean:.2f} $\\pm$ {sd:.2f}"


def difficulty_label(name: str) -> str:
    return f"{name.capitalize()} difficulty"


def table_terrains(table: pd.DataFrame) -> list[str]:
    """The evaluation terrains of `table`, in column order; one nobody registered fails
    loudly rather than being dropped from the table."""
    present = set(table["terrain"])
    known = eval_terrains()
    unknown = sorted(present - set(known))
    if unknown:
        raise ValueError(
            f"results name unregistered evaluation terrain(s) {unknown}; known: {known}"
        )
    return [t for t in known if t in present]


def across_seed_count(seeds: pd.DataFrame | None) -> int:
    """The fewest training seeds behind any row of a seed table (0: none given). With two or
    more everywhere, the simulation table shows the across-seed IQM and its CI."""
    return 0 if seeds is None or seeds.empty else int(seeds["n_seeds"].min())


def sim_caption(seeds: int) -> str:
    """What the simulation table's cells are: unit spread, or across-seed statistics."""
    if seeds >= 2:
        return (
            f"interquartile mean across training seeds (at least {seeds}) of each seed's mean "
            "over units [95 \\% stratified bootstrap CI, units resampled within each seed]"
        )
    return "mean $\\pm$ standard deviation across units"


def wide_table(
    table: pd.DataFrame, seeds: pd.DataFrame | None = None
) -> tuple[pd.DataFrame, pd.DataFrame]:
    """(display strings, numeric means), indexed (difficulty block, policy), columns
    (terrain, metric label), in the paper's layout. Given a seed table whose rows all rest on
    two or more seeds, the cells are its IQM across seeds with the CI."""
    present = set(table["difficulty"])
    diffs = [d for d in DIFFICULTY_ORDER if d in present]
    diffs += sorted(present - set(DIFFICULTY_ORDER))
    terrains = table_terrains(table)
    policies = sorted(table["policy"].unique(), key=row_key)
    index = pd.MultiIndex.from_product([[difficulty_label(d) for d in diffs], policies])
    labels = [eval_label(t) for t in terrains]
    columns = pd.MultiIndex.from_product([labels, list(METRICS.values())])
    text = pd.DataFrame("--", index=index, columns=columns)
    means = pd.DataFrame(np.nan, index=index, columns=columns)
    if across_seed_count(seeds) >= 2:
        for row in seeds.itertuples():
            key = (difficulty_label(row.difficulty), row.policy)
            col = (eval_label(row.terrain), METRICS[row.metric])
            text.loc[key, col] = f"{row.iqm:.2f} [{row.iqm_ci_low:.2f}, {row.iqm_ci_high:.2f}]"
            means.loc[key, col] = row.iqm
        return text, means
    for row in table.itertuples():
        key = (difficulty_label(row.difficulty), row.policy)
        col = (eval_label(row.terrain), METRICS[row.metric])
        text.loc[key, col] = _cell_text(row.mean, row.sd, row.metric)
        means.loc[key, col] = row.mean
    return text, means


def best_mask(means: pd.DataFrame) -> pd.DataFrame:
    """True where a cell is the best of its column within its difficulty block."""
    mask = pd.DataFrame(False, index=means.index, columns=means.columns)
    inverse = {v: k for k, v in METRICS.items()}
    for block in means.index.get_level_values(0).unique():
        part = means.loc[block]
        for col in means.columns:
            values = part[col]
            if values.notna().sum() < 2:
                continue
            lower = inverse[col[1]] in LOWER_IS_BETTER
            best = values.min() if lower else values.max()
            for policy in values.index[np.isclose(values, best)]:
                mask.loc[(block, policy), col] = True
    return mask


def to_latex(text: pd.DataFrame, best: pd.DataFrame, note: str = "", seeds: int = 0) -> str:
    """Booktabs LaTeX via pandas Styler, best cells bold, difficulty blocks introduced by an
    italic row as in the paper, `\\cmidrule` under the terrain headers, centred and scaled
    to the text width (a `table*` in a two-column paper; needs booktabs and graphicx)."""
    styled = text.style.apply(
        lambda col: np.where(best[col.name], "textbf:--rwrap;", ""), axis=0
    ).hide(axis="index", level=0)
    caption = (
        "Simulation results: success rate ($\\uparrow$), contacts per step ($\\downarrow$), "
        f"tracking error ($\\downarrow$); {sim_caption(seeds)}."
    )
    latex = styled.to_latex(
        hrules=True,
        multicol_align="c",
        column_format="l" + "c" * text.shape[1],
        caption=caption + (f" {note}" if note else ""),
        label="tab:sim_results",
        position="t",
        environment="table*",
    )
    lines = latex.splitlines()
    first_row = lines.index("\\midrule") + 1
    lines = _group_rules(lines, text)
    first_row += 1
    blocks = text.index.get_level_values(0)
    starts = {i: b for i, b in enumerate(blocks) if i == 0 or blocks[i - 1] != b}
    width = text.shape[1] + 1
    out = lines[:first_row]
    for i, line in enumerate(lines[first_row : first_row + len(text)]):
        if i in starts:
            if i > 0:
                out.append("\\addlinespace[2pt]")
            out.append(f"\\multicolumn{{{width}}}{{l}}{{\\textit{{{starts[i]}}}}} \\\\")
        out.append(line)
    out += lines[first_row + len(text) :]
    return _fit_to_width("\n".join(out) + "\n")


def _group_rules(lines: list[str], text: pd.DataFrame) -> list[str]:
    """A `\\cmidrule(lr)` under each terrain's header, spanning its metric columns."""
    groups = text.columns.get_level_values(0)
    spans, start = [], 0
    for i in range(1, len(groups) + 1):
        if i == len(groups) or groups[i] != groups[start]:
            spans.append((start + 2, i + 1))  # LaTeX columns: the policy column is 1
            start = i
    header = next(i for i, line in enumerate(lines) if "\\multicolumn" in line)
    rule = "".join(f"\\cmidrule(lr){{{a}-{b}}}" for a, b in spans)
    return lines[: header + 1] + [rule] + lines[header + 1 :]


def _fit_to_width(latex: str) -> str:
    """Centre the tabular and scale it to the text width, as the paper does."""
    latex = latex.replace(
        "\\begin{tabular}", "\\centering\n\\resizebox{\\textwidth}{!}{%\n\\begin{tabular}", 1
    )
    return latex.replace("\\end{tabular}", "\\end{tabular}%\n}", 1)


def claim_table(runs: list[RunRecord]) -> pd.DataFrame:
    """Two-stage minus its one-stage twin (same actor, encoder, seed), per cell, for success
    and contacts/step: paired bootstrap CI over units (common random numbers)."""
    by_key = {(r.curriculum, r.actor, r.encoder, r.seed): r for r in runs if r.episodes is not None}
    rows = []
    for (curr, actor, encoder, seed), two in sorted(by_key.items()):
        one = by_key.get(("one", actor, encoder, seed))
        if curr != "two" or one is None:
            continue
        keys = ["cell_terrain", "cell_difficulty"]
        for (terrain, difficulty), cell_two in two.episodes.groupby(keys):
            cell_one = one.episodes[
                (one.episodes.cell_terrain == terrain)
                & (one.episodes.cell_difficulty == difficulty)
            ]
            for metric in ("success", "contacts_per_step"):
                diff = paired_difference(
                    unit_values(cell_two, metric),
                    unit_values(cell_one, metric),
                    RESAMPLES,
                    CONFIDENCE,
                    SEED,
                )
                rows.append(
                    {
                        "two_stage": two.label,
                        "one_stage": one.label,
                        "seed": seed,
                        "terrain": terrain,
                        "difficulty": difficulty,
                        "metric": metric,
                        **diff,
                    }
                )
    return pd.DataFrame(rows, columns=CLAIM_COLUMNS)
