"""The README's "Results" block, written from a report folder beside the paper's numbers:

    python -m lca.report.results reports/reference

prints three Markdown tables (success, contacts per step and tracking error per cell, "ours
(paper)") and a verdict on each of the paper's claims from the CIs: parity at medium
difficulty, and the paired two-stage - one-stage differences. The README
carries that block verbatim between `<!-- results:begin -->` and `<!-- results:end -->`;
tests/test_quoted_figures.py regenerates it from the files and compares, so a number in the
README is always the file's.
The paper's numbers are its simulation table (`assets/paper/sim_table.csv`).
"""

from __future__ import annotations

import sys
from pathlib import Path

import pandas as pd

from lca.paths import assets_dir
from lca.report.collect import row_key

BEGIN, END = "<!-- results:begin -->", "<!-- results:end -->"
CELLS = [  # the paper's four cells, then flat (not in the paper's table)
    ("stairs", "medium"),
    ("uneven", "medium"),
    ("stairs", "hard"),
    ("uneven", "hard"),
    ("flat", "medium"),
]
DIGITS = {"success": 1, "contacts_per_step": 2, "track_cm_s": 1}
CLAIMS = [  # (terrain, difficulty, metric) the paper's claims rest on
    ("uneven", "hard", "success"),
    ("stairs", "medium", "contacts_per_step"),
    ("stairs", "hard", "contacts_per_step"),
]
PAPER_GAIN = 10.0  # points: two-stage over one-stage on uneven hard, the paper's claim


def paper_table() -> pd.DataFrame:
    return pd.read_csv(assets_dir() / "paper" / "sim_table.csv")


def _means(table: pd.DataFrame, policy_col: str = "policy") -> dict[tuple, float]:
    keys = zip(table[policy_col], table.terrain, table.difficulty, table.metric, strict=True)
    return dict(zip(keys, table["mean"], strict=True))


def metric_table(ours: pd.DataFrame, paper: pd.DataFrame, metric: str) -> str:
    """Markdown: one row per policy of `ours`, one column per cell, "ours (paper)"."""
    mine, theirs = _means(ours), _means(paper)
    cells = [c for c in CELLS if any(k[1:3] == c for k in mine)]
    head = ["Policy", *(f"{t} {d}" for t, d in cells)]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    seeds = ours.groupby("policy")["n_seeds"].max() if "n_seeds" in ours else {}
    for policy in sorted(ours.policy.unique(), key=row_key):
        row = [_with_seeds(policy, seeds.get(policy, 1))]
        for terrain, difficulty in cells:
            value = mine.get((policy, terrain, difficulty, metric))
            text = "–" if value is None else f"{value:.{DIGITS[metric]}f}"
            quoted = theirs.get((policy, terrain, difficulty, metric))
            row.append(text if quoted is None else f"{text} ({quoted:g})")
        lines.append("| " + " | ".join(row) + " |")
    return "\n".join(lines)


def _with_seeds(policy: str, n_seeds) -> str:
    """A policy's row label; one pooling several training seeds' units says how many."""
    return policy if int(n_seeds) < 2 else f"{policy} ({int(n_seeds)} seeds)"


def _cell(table: pd.DataFrame, terrain: str, difficulty: str, metric: str) -> pd.DataFrame:
    """The rows of `table` (sim_table.csv or claim.csv) for one cell and metric."""
    sel = (table.terrain == terrain) & (table.difficulty == difficulty) & (table.metric == metric)
    return table[sel]


def _verdict(diff_low: float, diff_high: float, better: int) -> str:
    """'seen' when the CI lies on the claimed side of zero (`better` = +1 or -1), 'reversed'
    when it lies on the other side, else 'not decided (the CI spans 0)'."""
    if better * diff_low > 0 and better * diff_high > 0:
        return "seen"
    if better * diff_low < 0 and better * diff_high < 0:
        return "reversed"
    return "not decided (the CI spans 0)"


def _against_paper_gain(ci_low: float, ci_high: float) -> str:
    if ci_low > PAPER_GAIN:
        return f"larger than the paper's ~{PAPER_GAIN:g}"
    if ci_high < PAPER_GAIN:
        return f"smaller than the paper's ~{PAPER_GAIN:g}"
    return f"the paper's ~{PAPER_GAIN:g} inside the CI"


def claim_lines(claim: pd.DataFrame) -> str:
    """One bullet per twin pair and claim cell: the paired difference, its 95 % CI and the
    verdict on the paper's claim (two-stage succeeds more, by ~10 points on uneven hard, and
    makes fewer contacts on stairs)."""
    lines = []
    several = claim["seed"].nunique() > 1  # then each pair's bullets name their seed
    for terrain, difficulty, metric in CLAIMS:
        success = metric == "success"
        unit = "points" if success else "contacts/step"
        for r in _cell(claim, terrain, difficulty, metric).itertuples(index=False):
            seed = f" (seed {r.seed})" if several else ""
            verdict = _verdict(r.ci_low, r.ci_high, better=1 if success else -1)
            if success and verdict == "seen":
                verdict += ", " + _against_paper_gain(r.ci_low, r.ci_high)
            lines.append(
                f"- {r.two_stage} − {r.one_stage}{seed}, {terrain} {difficulty}: "
                f"{r.diff:+.{DIGITS[metric]}f} {unit} "
                f"[{r.ci_low:+.{DIGITS[metric]}f}, {r.ci_high:+.{DIGITS[metric]}f}]: {verdict}"
            )
    return "\n".join(lines) or "- no two-stage policy has its one-stage twin in this report"


def parity_lines(ours: pd.DataFrame) -> str:
    """The paper's parity claim at medium difficulty, per terrain: the lowest and highest
    success with their 95 % CIs; parity is seen when those two CIs overlap."""
    lines = []
    for terrain in ("stairs", "uneven"):
        rows = _cell(ours, terrain, "medium", "success").sort_values("mean")
        if len(rows) < 2:
            continue
        low, high = rows.iloc[0], rows.iloc[-1]
        verdict = "seen (the CIs overlap)" if low.ci_high >= high.ci_low else "not seen"
        name = {r.policy: _with_seeds(r.policy, r.get("n_seeds", 1)) for r in (low, high)}
        lines.append(
            f"- Parity, {terrain} medium: {name[low.policy]} {low['mean']:.1f} % "
            f"[{low.ci_low:.1f}, {low.ci_high:.1f}] to {name[high.policy]} {high['mean']:.1f} % "
            f"[{high.ci_low:.1f}, {high.ci_high:.1f}]: {verdict}"
        )
    return "\n".join(lines)


def results_block(report: Path) -> str:
    """The README's Results block, markers included."""
    report = Path(report)
    ours = pd.read_csv(report / "sim_table.csv")
    paper = paper_table()
    claim = pd.read_csv(report / "claim.csv")
    parts = [
        BEGIN,
        "Success (%), ours (paper):",
        "",
        metric_table(ours, paper, "success"),
        "",
        "Contacts per step, ours (paper):",
        "",
        metric_table(ours, paper, "contacts_per_step"),
        "",
        "Tracking error (cm/s), ours (paper); a robot standing still scores about 45:",
        "",
        metric_table(ours, paper, "track_cm_s"),
        "",
        "The paper's claims on these files (95 % bootstrap CIs; the differences paired over",
        "the same units):",
        "",
        parity_lines(ours),
        claim_lines(claim),
        END,
    ]
    return "\n".join(parts)


def readme_block(text: str) -> str | None:
    """The Results block a README carries, markers included (None without one)."""
    if BEGIN not in text or END not in text:
        return None
    return text[text.index(BEGIN) : text.index(END) + len(END)]


def main(argv: list[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else argv
    if len(args) != 1:
        print("usage: python -m lca.report.results <report folder>", file=sys.stderr)
        return 2
    print(results_block(Path(args[0])))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
