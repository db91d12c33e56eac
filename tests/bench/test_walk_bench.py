"""The time-to-walk benchmark: it probes the policy in-process, stops where it is told, leaves
a complete run, and calls a policy walking only under the paper's unclipped objective."""

from __future__ import annotations

import pandas as pd
import pytest
from _cli import SMOKE

from lca.bench import walk
from lca.bench.__main__ import result_name
from lca.store import RunDir

pytestmark = pytest.mark.slow  # trains, evaluates or runs a stage: see README


def two_iterations(tmp_path, *extra: str) -> list[str]:
    """A 2-iteration smoke walk probed once, at its last iteration, with 2 units."""
    return [
        *SMOKE,
        *extra,
        f"run={tmp_path / 'run'}",
        f"figure={tmp_path / 'walk.png'}",
        "iterations=2",
        "eval_every_s=0",
        "eval_from=2",
        "eval.units=2",
        "eval.steps=20",
    ]


def test_until_stops_a_probed_run_that_is_complete(tmp_path):
    out = walk.run(
        [
            *SMOKE,
            f"run={tmp_path / 'run'}",
            f"figure={tmp_path / 'walk.png'}",
            "iterations=6",
            "until=3",
            "eval_every_s=0",
            "eval_from=2",
            "eval.units=2",
            "eval.steps=20",
        ],
        log=None,
    )
    run = tmp_path / "run"
    curve = pd.read_csv(run / "train_curve.csv")
    assert list(curve["iteration"]) == [0, 1, 2]  # stopped after `until` iterations of 6
    probes = pd.read_csv(run / "probe_evals.csv")
    # every iteration probed (eval_every_s=0) from the second (iteration 1) on
    assert list(probes["iteration"]) == [1, 2]
    assert set(probes["paper_objective"]) == {1}  # smoke: no curriculum, no clipping
    assert probes["still_cm_s"].notna().all()  # the zero-command probe ran each time
    assert (run / "COMPLETE").is_file() and (tmp_path / "walk.png").stat().st_size > 0
    assert (run / "exported" / "policy.onnx").is_file()
    assert out["env_steps"] == int(curve["env_steps"].iloc[-1])
    assert result_name("walk", out) == "walk.json"  # the flat time-to-walk's file


def test_walking_needs_the_paper_objective():
    row = {"success": 100.0, "track_cm_s": 10.0, "still_cm_s": 3.0, "penalty_scale": 1.0}
    assert walk.walks({**row, "paper_objective": 1})
    assert not walk.walks({**row, "paper_objective": 0})  # clipped or penalties scaled
    assert not walk.walks({**row, "paper_objective": 1, "track_cm_s": 25.0})
    assert not walk.walks({**row, "paper_objective": 1, "success": 80.0})
    # a forward walker that ignores the command: it walks on when told to stand
    assert not walk.walks({**row, "paper_objective": 1, "still_cm_s": 40.0})
    assert not walk.walks(
        {k: v for k, v in row.items() if k != "still_cm_s"} | {"paper_objective": 1}
    )


def test_walking_on_terrain_needs_stairs_and_uneven():
    row = {"success": 100.0, "track_cm_s": 10.0, "still_cm_s": 3.0, "paper_objective": 1}
    row |= {"penalty_scale": 1.0, "stairs_success": 85.0, "uneven_success": 81.0}
    assert walk.walks(row)
    assert not walk.walks({**row, "stairs_success": 79.0})
    assert not walk.walks({**row, "uneven_success": 50.0})
    assert walk.walks({**row, "stairs_success": float("nan"), "uneven_success": float("nan")})


def test_a_run_on_terrain_is_probed_on_stairs_and_uneven(tmp_path, monkeypatch):
    out = walk.run(two_iterations(tmp_path, "terrain=mixed"), log=None)
    probes = pd.read_csv(tmp_path / "run" / "probe_evals.csv")
    assert list(probes["iteration"]) == [1]
    for key in ("stairs_success", "uneven_success"):
        assert 0.0 <= probes[key].iloc[0] <= 100.0, probes.to_dict()
    # its own result file, so a terrain run does not overwrite the flat time-to-walk
    assert result_name("walk", out) == "walk_terrain.json"
    # and a lever's run names its own, figure included
    opts = {**walk.OPTIONS, "variant": "terrain_r5"}
    monkeypatch.setattr(walk, "REPORTS", tmp_path)
    (tmp_path / "bench").mkdir()
    again = walk.summarise(RunDir(tmp_path / "run"), [], opts, None)
    assert result_name("walk", again) == "walk_terrain_r5.json"
    assert (tmp_path / "bench" / "walk_terrain_r5.png").exists()


def test_a_terrain_runs_figure_plots_its_stairs_and_uneven_probes(tmp_path, monkeypatch):
    evals = pd.DataFrame(
        {
            "iteration": [9, 19],
            "env_steps": [1e6, 2e6],
            "train_wall_s": [60.0, 120.0],
            "penalty_scale": [1.0, 1.0],
            "paper_objective": [0, 1],
            "success": [100.0, 100.0],
            "track_cm_s": [30.0, 25.0],
            "still_cm_s": [5.0, 5.0],
            "stairs_success": [10.0, 20.0],
            "uneven_success": [70.0, 60.0],
        }
    )
    figures = []
    monkeypatch.setattr(walk.plt, "close", figures.append)
    walk.plot(evals, tmp_path / "walk.png")
    success = figures[0].axes[0]
    curves = {line.get_label(): list(line.get_ydata()) for line in success.get_lines()}
    assert curves["stairs-medium"] == [10.0, 20.0]
    assert curves["uneven-medium"] == [70.0, 60.0]
    assert (tmp_path / "walk.png").stat().st_size > 0
    flat = evals.drop(columns=["stairs_success", "uneven_success"])
    figures.clear()
    walk.plot(flat, tmp_path / "flat.png")
    assert "stairs-medium" not in {line.get_label() for line in figures[0].axes[0].get_lines()}


@pytest.mark.parametrize("confirm_units, agrees", [(3, True), (3, False), (0, True)])
def test_a_walking_probe_is_confirmed_by_a_larger_evaluation(
    tmp_path, monkeypatch, confirm_units, agrees
):
    def probes_walk(row: dict) -> bool:  # the 2-unit probe "walks"; the larger one: `agrees`
        return row["units"] == 2 or agrees

    monkeypatch.setattr(walk, "walks", probes_walk)
    out = walk.run(two_iterations(tmp_path, f"confirm_units={confirm_units}"), log=None)
    probes = pd.read_csv(tmp_path / "run" / "probe_evals.csv")
    if confirm_units:
        # the probe's row, then the confirmation's: same iteration, more units
        assert list(probes["iteration"]) == [1, 1]
        assert list(probes["units"]) == [2, 3] and list(probes["confirm"]) == [0, 1]
    else:
        assert list(probes["units"]) == [2] and list(probes["confirm"]) == [0]
    assert out["walked"] is agrees
    assert out["iterations_to_walk"] == (2 if agrees else None)
    assert out["probe"]["confirm_units"] == confirm_units
    assert (tmp_path / "walk.png").stat().st_size > 0


def test_an_unconfirmed_probe_does_not_walk():
    row = {"success": 100.0, "track_cm_s": 10.0, "still_cm_s": 3.0, "paper_objective": 1}
    row |= {"penalty_scale": 1.0, "units": 64, "confirm": 0}
    assert walk.walks(row) and not walk.counts(row, 256)
    assert walk.counts({**row, "units": 256, "confirm": 1}, 256)
    assert walk.counts(row, 0)  # no confirmation asked for
    assert not walk.counts({**row, "confirm": 1, "track_cm_s": 30.0}, 256)
