"""The report of a hand-made run store: tables against golden files, LaTeX that compiles, rows
labelled from configs (never folder names), the paired claim, the training figure, and the CLI.
"""

from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import matplotlib.image
import numpy as np
import pandas as pd
import pytest

from lca.evaluate.metrics import METRICS
from lca.report.__main__ import main as report_main
from lca.report.build import build_report
from lca.report.collect import find_run_dirs, load_run
from lca.report.figures import SMOOTH, reward_curves

from .helpers import (
    NOT_A_RUN,
    cell_units,
    check_golden,
    fixture_cells,
    fixture_spec,
    percentile_bootstrap,
    train_curve,
)

LABELS = {
    "blind": "Blind",
    "one_mlp": "One-Stage MLP",
    "two_mlp": "Two-Stage MLP",
    "one_lstm": "One-Stage LSTM",
}
ROWS = ["Blind", "One-Stage MLP", "Two-Stage MLP"]  # the evaluated policies, paper order
TERRAINS = {"stairs": "Stairs", "uneven": "Uneven Terrain"}  # the fixture store's terrains
DIFFICULTIES = ("medium", "hard")
BOLD = r"\textbf{"


# ---- golden files ------------------------------------------------------------------------


@pytest.mark.parametrize("name", ["sim_table.csv", "sim_table.tex", "claim.csv"])
def test_matches_golden(fixture_report: Path, name: str) -> None:
    check_golden(fixture_report / name, name)


def test_table_cis_match_an_independent_bootstrap(fixture_store: Path, fixture_report: Path):
    """Each row's CI against a percentile bootstrap written in the test, over unit values
    worked out from the raw episodes (seeds pooled): endpoints agree within a tenth of the
    units' range, and the CI holds the mean."""
    units: dict[tuple, dict[str, float]] = {}
    for run in fixture_spec()["runs"]:
        path = fixture_store / run["folder"] / "results.parquet"
        if not path.exists():
            continue
        episodes = pd.read_parquet(path)
        for (terrain, difficulty), cell in episodes.groupby(["cell_terrain", "cell_difficulty"]):
            for metric in ("success", "contacts_per_step", "track_cm_s"):
                per_unit = cell.groupby("unit")[metric].mean()
                key = (LABELS[run["policy"]], terrain, difficulty, metric)
                for unit, value in per_unit.items():
                    units.setdefault(key, {})[f"{run['seed']}:{unit}"] = value
    table = pd.read_csv(fixture_report / "sim_table.csv")
    assert len(table) == len(units)
    for row in table.itertuples():
        values = np.array(
            list(units[(row.policy, row.terrain, row.difficulty, row.metric)].values())
        )
        low, high = percentile_bootstrap(values, 0.95, 20000, seed=1)
        slack = 0.1 * (values.max() - values.min()) + 1e-9
        assert abs(row.ci_low - low) <= slack and abs(row.ci_high - high) <= slack, row
        assert row.ci_low - 1e-9 <= row.mean <= row.ci_high + 1e-9


def test_report_files(fixture_report: Path) -> None:
    for name in (
        "sim_table.tex",
        "sim_table.csv",
        "claim.csv",
        "training_rewards.png",
        "training_rewards.pdf",
        "index.html",
    ):
        path = fixture_report / name
        assert path.is_file() and path.stat().st_size > 0, name


# ---- the table ---------------------------------------------------------------------------


def _latex_rows(tex: str) -> dict[str, list[list[str]]]:
    """Body rows of the LaTeX table per difficulty block: {block: [[policy, cell, ...]]}."""
    blocks: dict[str, list[list[str]]] = {}
    block = None
    for line in tex.splitlines():
        if line.startswith(r"\multicolumn{7}{l}{\textit{"):
            block = line.split(r"\textit{")[1].split("}")[0]
            blocks[block] = []
        elif block and line.endswith(r"\\") and not line.startswith("\\"):
            blocks[block].append([c.strip() for c in line[:-2].split("&")])
    return blocks


def test_latex_layout_and_best_cells(fixture_report: Path) -> None:
    """Paper layout: Blind first, blocks Medium then Hard, best per column and block in bold
    (higher success, lower contacts/step and tracking error; ties all bold)."""
    tex = (fixture_report / "sim_table.tex").read_text()
    assert tex.startswith(r"\begin{table*}") and r"\toprule" in tex and r"\bottomrule" in tex
    assert r"\centering" in tex and r"\resizebox{\textwidth}" in tex
    assert r"\cmidrule(lr){2-4}\cmidrule(lr){5-7}" in tex  # under Stairs and Uneven Terrain
    assert "standard deviation across units" in tex
    for label in (*TERRAINS.values(), *METRICS.values()):
        assert label in tex
    blocks = _latex_rows(tex)
    assert list(blocks) == ["Medium difficulty", "Hard difficulty"]
    for rows in blocks.values():
        assert [r[0] for r in rows] == ROWS
        assert all(len(r) == 7 for r in rows)
    bold = {
        block: [[i for i, c in enumerate(r[1:]) if c.startswith(BOLD)] for r in rows]
        for block, rows in blocks.items()
    }
    # columns: stairs (succ, contacts, track), uneven (succ, contacts, track); see cells.csv
    assert bold["Medium difficulty"] == [[0, 2], [0, 1], [2, 3, 4, 5]]
    assert bold["Hard difficulty"] == [[4], [], [0, 1, 2, 3, 5]]
    blind_medium = blocks["Medium difficulty"][0]
    assert blind_medium[1] == r"\textbf{100.00}"  # success: mean only
    table = pd.read_csv(fixture_report / "sim_table.csv").set_index(
        ["policy", "terrain", "difficulty", "metric"]
    )
    row = table.loc[("Blind", "stairs", "medium", "contacts_per_step")]
    assert row["sd"] == pytest.approx(row["se"] * np.sqrt(row["n_units"]))
    assert row["n_units"] > 1 and row["sd"] > row["se"]  # the spread, not the standard error
    assert blind_medium[2] == rf"{row['mean']:.2f} $\pm$ {row['sd']:.2f}"  # mean $\pm$ SD


def test_latex_compiles(fixture_report: Path, tmp_path: Path) -> None:
    pdflatex = shutil.which("pdflatex")
    if pdflatex is None:
        pytest.skip("pdflatex is not installed (TeX Live); cannot compile sim_table.tex")
    shutil.copy(fixture_report / "sim_table.tex", tmp_path / "sim_table.tex")
    (tmp_path / "doc.tex").write_text(
        "\\documentclass{article}\n\\usepackage{booktabs}\n\\usepackage{graphicx}\n"
        "\\begin{document}\n\\input{sim_table.tex}\n\\end{document}\n"
    )
    out = subprocess.run(
        [pdflatex, "-interaction=nonstopmode", "-halt-on-error", "doc.tex"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    assert out.returncode == 0, out.stdout[-3000:]
    assert (tmp_path / "doc.pdf").stat().st_size > 1000
    assert "Undefined control sequence" not in out.stdout
    log = (tmp_path / "doc.log").read_text(errors="replace")
    overfull = [float(m) for m in re.findall(r"Overfull \\hbox \(([\d.]+)pt too wide", log)]
    assert all(w <= 1.0 for w in overfull), overfull


def test_long_table_values(fixture_report: Path) -> None:
    """Means are the cells.csv values (unit offsets sum to zero); seeds pool as more units."""
    table = pd.read_csv(fixture_report / "sim_table.csv")
    assert list(table.columns) == [
        "policy",
        "terrain",
        "difficulty",
        "metric",
        "n_seeds",
        "mean",
        "sd",
        "se",
        "ci_low",
        "ci_high",
        "n_units",
    ]
    assert list(table["policy"].drop_duplicates()) == ROWS  # Blind first, no unevaluated run
    assert len(table) == len(ROWS) * len(TERRAINS) * len(DIFFICULTIES) * len(METRICS)
    got = table.set_index(["policy", "terrain", "difficulty", "metric"])
    cells = fixture_cells()
    runs = {r["folder"]: r for r in fixture_spec()["runs"]}
    cells["policy"] = [LABELS[runs[f]["policy"]] for f in cells["folder"]]
    pooled = cells.groupby(["policy", "terrain", "difficulty"])[["contacts", "track"]].mean()
    for (policy, terrain, difficulty), row in pooled.iterrows():
        key = (policy, terrain, difficulty)
        assert got.loc[(*key, "contacts_per_step"), "mean"] == pytest.approx(row.contacts)
        assert got.loc[(*key, "track_cm_s"), "mean"] == pytest.approx(row.track)
    two = got.loc[("Two-Stage MLP", "stairs", "hard", "success")]
    assert (two["n_seeds"], two["n_units"]) == (2, 8)
    assert two["mean"] == pytest.approx(93.75)  # seed 0: no failure; seed 1: one of 8
    blind = got.loc[("Blind", "uneven", "hard", "success")]  # units 50, 50, 50, 100
    assert blind["mean"] == pytest.approx(62.5) and blind["se"] == pytest.approx(12.5)
    assert (blind["n_seeds"], blind["n_units"]) == (1, 4)
    for row in table.itertuples():
        assert row.ci_low <= row.mean + 1e-9 and row.mean <= row.ci_high + 1e-9


# ---- rows from configs, not folder names -------------------------------------------------


def test_labels_follow_configs(fixture_store: Path) -> None:
    found = find_run_dirs([fixture_store])
    spec = fixture_spec()["runs"]
    assert sorted(p.name for p in found) == sorted(r["folder"] for r in spec)
    assert NOT_A_RUN not in {p.name for p in found} and "report" not in {p.name for p in found}
    for run in spec:
        record = load_run(fixture_store / run["folder"])
        assert record.label == LABELS[run["policy"]], run["folder"]
        assert record.seed == run["seed"]
    # the misleading folder "policy=two_mlp,seed=0" holds the one-stage run
    assert load_run(fixture_store / "policy=two_mlp,seed=0").label == "One-Stage MLP"


def test_misleading_folder_rows_carry_their_configs_data(fixture_report: Path) -> None:
    table = pd.read_csv(fixture_report / "sim_table.csv")
    row = table[
        (table.policy == "One-Stage MLP")
        & (table.terrain == "uneven")
        & (table.difficulty == "hard")
        & (table.metric == "contacts_per_step")
    ]
    # cells.csv: folder "policy=two_mlp,seed=0" (a one_mlp config) has 3.40 there
    assert row["mean"].item() == pytest.approx(3.40)


def test_single_run_dirs_and_empty_paths(fixture_store: Path, tmp_path: Path) -> None:
    blind = fixture_store / "aaa_policy=two_cnn"
    assert find_run_dirs([blind]) == [blind]
    index = build_report([blind], tmp_path / "one")
    table = pd.read_csv(index.parent / "sim_table.csv")
    assert set(table["policy"]) == {"Blind"}
    with pytest.raises(FileNotFoundError):
        build_report([fixture_store / NOT_A_RUN], tmp_path / "none")


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


def test_claim_csv_without_a_pair_has_a_header(fixture_store: Path, tmp_path: Path) -> None:
    index = build_report([fixture_store / "aaa_policy=two_cnn"], tmp_path / "blind")
    claim = pd.read_csv(index.parent / "claim.csv")
    assert list(claim.columns) == CLAIM_COLUMNS and claim.empty


# ---- the claim ---------------------------------------------------------------------------


def test_claim_pairs_two_stage_with_its_one_stage_twin(fixture_store: Path, fixture_report):
    claim = pd.read_csv(fixture_report / "claim.csv")
    assert list(claim.columns) == CLAIM_COLUMNS
    assert set(claim["two_stage"]) == {"Two-Stage MLP"}
    assert set(claim["one_stage"]) == {"One-Stage MLP"}
    assert set(claim["seed"]) == {0}  # seed 1 has no one-stage twin
    assert set(claim["metric"]) == {"success", "contacts_per_step"}
    assert len(claim) == len(TERRAINS) * len(DIFFICULTIES) * 2
    assert not claim.duplicated(["terrain", "difficulty", "metric"]).any()
    two = pd.read_parquet(fixture_store / "policy=one_mlp,seed=0" / "results.parquet")
    one = pd.read_parquet(fixture_store / "policy=two_mlp,seed=0" / "results.parquet")
    for row in claim.itertuples():
        key = (row.terrain, row.difficulty, row.metric)
        diff = cell_units(two, *key) - cell_units(one, *key)
        assert row.diff == pytest.approx(diff.mean())
        assert row.n_units == 4
        assert row.ci_low <= row.diff + 1e-9 and row.diff <= row.ci_high + 1e-9
    contacts = claim[claim.metric == "contacts_per_step"].set_index(["terrain", "difficulty"])
    # same per-unit offsets in both runs: a constant paired shift, a zero-width CI
    assert contacts.loc[("stairs", "hard"), "diff"] == pytest.approx(0.60 - 1.60)
    assert contacts.loc[("stairs", "hard"), "ci_high"] < 0
    assert contacts.loc[("stairs", "medium"), "diff"] == pytest.approx(1.00 - 0.60)
    assert contacts.loc[("stairs", "medium"), "ci_low"] > 0


# ---- the training figure -----------------------------------------------------------------


def test_training_curves(fixture_store: Path, fixture_report: Path) -> None:
    runs = [load_run(p) for p in find_run_dirs([fixture_store])]
    curves = reward_curves(runs)
    assert list(curves) == ["Blind", "One-Stage MLP", "Two-Stage MLP", "One-Stage LSTM"]
    index = {r["folder"]: i for i, r in enumerate(fixture_spec()["runs"])}

    def smooth(folder):
        curve = train_curve(index[folder]).set_index("iteration")["mean_reward"]
        return curve.rolling(SMOOTH, min_periods=1).mean()

    seeds = pd.concat([smooth("policy=one_mlp,seed=0"), smooth("policy=two_mlp,seed=1")], axis=1)
    two = curves["Two-Stage MLP"]
    np.testing.assert_allclose(two["mean"], seeds.mean(axis=1))
    np.testing.assert_allclose(two["low"], seeds.min(axis=1))
    np.testing.assert_allclose(two["high"], seeds.max(axis=1))
    blind = curves["Blind"]  # one seed: +- rolling std band around the mean
    np.testing.assert_allclose(blind["mean"], smooth("aaa_policy=two_cnn"))
    band = blind.dropna()  # iteration 0 has no finished episode
    assert len(band) == len(blind) - 1
    assert (band["low"] <= band["mean"]).all() and (band["mean"] <= band["high"]).all()
    assert (band["high"] - band["low"]).iloc[1:].gt(0).all()

    png = matplotlib.image.imread(fixture_report / "training_rewards.png")
    assert png.ndim == 3 and png.shape[0] > 300 and png.shape[1] > 500
    assert png[..., :3].std() > 0.05  # not a blank canvas
    assert (fixture_report / "training_rewards.pdf").read_bytes().startswith(b"%PDF")


# ---- the CLI -----------------------------------------------------------------------------


def test_cli(fixture_store: Path, fixture_report: Path, tmp_path: Path, capsys) -> None:
    assert report_main([]) == 2
    out = tmp_path / "cli"
    assert report_main([str(fixture_store), f"out={out}"]) == 0
    assert str(out / "index.html") in capsys.readouterr().out
    for name in ("sim_table.csv", "sim_table.tex", "claim.csv"):
        assert (out / name).read_text() == (fixture_report / name).read_text(), name
    # run directories given one by one; the unevaluated run changes nothing in the tables
    runs = [fixture_store / r["folder"] for r in fixture_spec()["runs"]]
    out2 = tmp_path / "cli2"
    assert report_main([*map(str, runs), f"out={out2}"]) == 0
    for name in ("sim_table.csv", "sim_table.tex", "claim.csv"):
        assert (out2 / name).read_text() == (fixture_report / name).read_text(), name
