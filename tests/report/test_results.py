"""The README's Results block: each claim's verdict follows from the CIs in the files."""

from __future__ import annotations

import pandas as pd
import pytest

from lca.report import results


def claim_row(metric: str, terrain: str, difficulty: str, ci: tuple[float, float]) -> dict:
    low, high = ci
    return {
        "two_stage": "Two-Stage CNN",
        "one_stage": "One-Stage CNN",
        "seed": 0,
        "terrain": terrain,
        "difficulty": difficulty,
        "metric": metric,
        "diff": (low + high) / 2,
        "ci_low": low,
        "ci_high": high,
        "n_units": 128,
    }


@pytest.mark.parametrize(
    ("ci", "verdict"),
    [
        ((14.0, 30.0), "seen, larger than the paper's ~10"),
        ((4.0, 16.0), "seen, the paper's ~10 inside the CI"),
        ((2.0, 6.0), "seen, smaller than the paper's ~10"),
        ((-3.0, 5.0), "not decided (the CI spans 0)"),
        ((-9.0, -2.0), "reversed"),
    ],
)
def test_uneven_hard_gain_verdict(ci: tuple[float, float], verdict: str) -> None:
    claim = pd.DataFrame([claim_row("success", "uneven", "hard", ci)])
    line = results.claim_lines(claim)
    assert line.startswith("- Two-Stage CNN − One-Stage CNN, uneven hard: ")
    assert line.endswith(f"]: {verdict}")


@pytest.mark.parametrize(
    ("ci", "verdict"),
    [((-0.9, -0.6), "seen"), ((0.2, 0.5), "reversed"), ((-0.2, 0.1), "not decided")],
)
def test_fewer_contacts_on_stairs_is_a_negative_difference(ci, verdict: str) -> None:
    claim = pd.DataFrame(
        [
            claim_row("contacts_per_step", "stairs", "medium", ci),
            claim_row("success", "flat", "medium", ci),
        ]
    )
    lines = results.claim_lines(claim).splitlines()
    assert len(lines) == 1  # flat is no claim's cell
    assert f"[{ci[0]:+.2f}, {ci[1]:+.2f}]: {verdict}" in lines[0]


def sim_row(policy: str, terrain: str, mean: float, half_width: float) -> dict:
    return {
        "policy": policy,
        "terrain": terrain,
        "difficulty": "medium",
        "metric": "success",
        "mean": mean,
        "ci_low": mean - half_width,
        "ci_high": mean + half_width,
    }


def test_parity_is_seen_when_the_lowest_and_highest_cis_overlap() -> None:
    ours = pd.DataFrame(
        [
            sim_row("Blind", "stairs", 96.0, 2.0),
            sim_row("One-Stage MLP", "stairs", 93.0, 2.5),
            sim_row("Two-Stage MLP", "stairs", 95.0, 2.0),
            sim_row("Blind", "uneven", 97.0, 1.0),
            sim_row("One-Stage MLP", "uneven", 70.0, 5.0),
        ]
    )
    stairs, uneven = results.parity_lines(ours).splitlines()
    assert stairs == (
        "- Parity, stairs medium: One-Stage MLP 93.0 % [90.5, 95.5] to Blind 96.0 % "
        "[94.0, 98.0]: seen (the CIs overlap)"
    )
    assert uneven.startswith("- Parity, uneven medium: One-Stage MLP 70.0 %")
    assert uneven.endswith(": not seen")


def test_parity_needs_two_policies() -> None:
    assert results.parity_lines(pd.DataFrame([sim_row("Blind", "stairs", 96.0, 2.0)])) == ""


def test_rows_and_pairs_with_several_seeds_say_so() -> None:
    """A row that pools two training seeds' units names the count, and with several seeds
    each paired difference names its seed; one seed everywhere reads as before."""
    ours = pd.DataFrame(
        [sim_row("Blind", "stairs", 96.0, 2.0), sim_row("Two-Stage MLP", "stairs", 90.0, 2.0)]
    )
    ours["n_seeds"] = [1, 2]
    table = results.metric_table(ours, pd.DataFrame(columns=ours.columns), "success")
    assert "| Two-Stage MLP (2 seeds) | 90.0 |" in table and "| Blind | 96.0 |" in table
    assert "Two-Stage MLP (2 seeds) 90.0 %" in results.parity_lines(ours)

    first = claim_row("success", "uneven", "hard", (4.0, 16.0))
    second = first | {"seed": 1, "ci_low": -2.0, "ci_high": 1.0}
    lines = results.claim_lines(pd.DataFrame([first, second])).splitlines()
    assert lines[0].startswith("- Two-Stage CNN − One-Stage CNN (seed 0), uneven hard: ")
    assert lines[1].startswith("- Two-Stage CNN − One-Stage CNN (seed 1), uneven hard: ")
    assert "(seed" not in results.claim_lines(pd.DataFrame([first]))
