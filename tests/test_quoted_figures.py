"""The figures the README and reports/benchmarks.md quote for a shipped policy are the ones in
its summary.csv, to the digits quoted."""

from __future__ import annotations

import functools
import re

import pandas as pd
import pytest

from lca.paths import root
from lca.report import results

# "<success> % success, <track> cm/s tracking" quoted for a policy, and where it ships
QUOTE = re.compile(r"(\d+(?:\.\d+)?) % success, (\d+\.\d+) cm/s tracking")
QUOTED = {
    "README.md": "blind_flat",
    "reports/benchmarks.md": "blind_flat",
}


@functools.cache
def shipped_summary(policy: str) -> pd.DataFrame:
    return pd.read_csv(root() / "assets" / "policies" / policy / "summary.csv")


def shipped_cell(policy: str, terrain: str, difficulty: str) -> pd.DataFrame:
    """A shipped policy's summary.csv rows of one cell, indexed by metric."""
    summary = shipped_summary(policy)
    cell = summary[(summary.cell_terrain == terrain) & (summary.cell_difficulty == difficulty)]
    return cell.set_index("metric")


def flat_cell(policy: str) -> dict[str, float]:
    return shipped_cell(policy, "flat", "medium")["mean"].to_dict()


@pytest.mark.parametrize(("doc", "policy"), sorted(QUOTED.items()))
def test_quoted_flat_cell_figures_match_the_shipped_summary(doc: str, policy: str) -> None:
    text = (root() / doc).read_text()
    quotes = QUOTE.findall(text)
    assert quotes, f"{doc} quotes no '<n> % success, <x> cm/s tracking' figure"
    metrics = flat_cell(policy)
    for success, track in quotes:
        assert float(success) == pytest.approx(metrics["success"], abs=0.5), (doc, success)
        decimals = len(track.split(".")[1])
        assert float(track) == round(metrics["track_cm_s"], decimals), (doc, track)


# reports/learning.md's table of the reference recipe: a row per shipped policy, one column
# per cell in this order, each "success [CI] / tracking / contacts per step"
LEARNING_ROWS = {
    "**Q1 (the default)**": "blind",
    "Q1, One-Stage MLP": "one_mlp",
    "Q1, Two-Stage MLP": "two_mlp",
    "Q1, One-Stage CNN": "one_cnn",
    "Q1, Two-Stage CNN": "two_cnn",
    "Q1, One-Stage MLP, seed 1": "one_mlp-seed1",
    "Q1, Two-Stage MLP, seed 1": "two_mlp-seed1",
    "Q1, Blind, seed 1": "blind-seed1",
    "Q1, One-Stage CNN, seed 1": "one_cnn-seed1",
    "Q1, Two-Stage CNN, seed 1": "two_cnn-seed1",
}
LEARNING_CELLS = [("flat", "medium"), ("stairs", "medium"), ("stairs", "hard")]
LEARNING_CELLS += [("uneven", "medium"), ("uneven", "hard")]
CELL_QUOTE = re.compile(r"(\d+(?:\.\d)?)(?: \[(\d+\.\d), (\d+\.\d)\])? / (\d+\.\d) / (\d+\.\d\d)")


def learning_rows() -> dict[str, list[str]]:
    rows = {}
    for line in (root() / "reports" / "learning.md").read_text().splitlines():
        cols = [c.strip() for c in line.strip().strip("|").split("|")]
        # the longest label first: a seed's row is not its policy's
        for label in sorted(LEARNING_ROWS, key=len, reverse=True):
            if cols[0].startswith(label):
                rows[LEARNING_ROWS[label]] = cols[1 : 1 + len(LEARNING_CELLS)]
                break
    return rows


def test_learning_md_quotes_each_shipped_reference_policys_summary() -> None:
    rows = learning_rows()
    assert set(LEARNING_ROWS.values()) <= rows.keys()
    for policy, cols in rows.items():
        for (terrain, difficulty), text in zip(LEARNING_CELLS, cols, strict=True):
            quote = CELL_QUOTE.fullmatch(text)
            assert quote, (policy, terrain, difficulty, text)
            m = shipped_cell(policy, terrain, difficulty)
            success, low, high, track, contacts = quote.groups()
            where = (policy, terrain, difficulty)
            assert float(success) == pytest.approx(m.loc["success", "mean"], abs=0.05), where
            if low is not None:
                assert float(low) == round(m.loc["success", "ci_low"], 1), where
                assert float(high) == round(m.loc["success", "ci_high"], 1), where
            assert float(track) == round(m.loc["track_cm_s", "mean"], 1), where
            assert float(contacts) == round(m.loc["contacts_per_step", "mean"], 2), where


def test_the_readme_results_are_the_reference_report_beside_the_paper() -> None:
    """The README's Results block is exactly what `python -m lca.report.results` writes from
    reports/reference/ and the paper's table: every number in it is a file's."""
    block = results.readme_block((root() / "README.md").read_text())
    assert block is not None, "README.md has no Results block (lca.report.results markers)"
    assert block == results.results_block(root() / "reports" / "reference")


PAPER = root().parent / "shared" / "reference" / "paper.tex"


@pytest.mark.skipif(not PAPER.exists(), reason="the paper is not beside the checkout")
def test_the_papers_numbers_are_its_simulation_table() -> None:
    tex = PAPER.read_text()
    start = tex.index(r"\label{tab:sim_results_two_tasks}")
    body = tex[start : tex.index(r"\end{tabular}", start)]
    paper = results.paper_table()
    quoted = {f"{v:g}" for v in paper["mean"]} | {f"{v:g}" for v in paper["sd"].dropna()}
    in_tex = {f"{float(x):g}" for x in re.findall(r"\d+\.\d+", body)}
    assert quoted == in_tex
    assert len(paper) == 14 * 6  # 7 policies x 2 difficulties x 2 terrains x 3 metrics
    row = paper[(paper.policy == "Two-Stage CNN") & (paper.difficulty == "hard")]
    assert row.set_index(["terrain", "metric"])["mean"].to_dict()[("uneven", "success")] == 71.95
