"""The figures the README and reports/benchmarks.md quote for a shipped policy are the ones in
its summary.csv, to the digits quoted."""

from __future__ import annotations

import re

import pandas as pd
import pytest

from lca.paths import root

# "<success> % success, <track> cm/s tracking" quoted for a policy, and where it ships
QUOTE = re.compile(r"(\d+(?:\.\d+)?) % success, (\d+\.\d+) cm/s tracking")
QUOTED = {
    "README.md": "blind_flat",
    "reports/benchmarks.md": "blind_flat",
}


def flat_cell(policy: str) -> dict[str, float]:
    summary = pd.read_csv(root() / "assets" / "policies" / policy / "summary.csv")
    flat = summary[(summary.cell_terrain == "flat") & (summary.cell_difficulty == "medium")]
    return dict(zip(flat.metric, flat["mean"], strict=True))


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
