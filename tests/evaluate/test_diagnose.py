"""The diagnosis of a trained run: each command held, the reached velocity and every reward
term per second under the paper's table."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from lca.evaluate import diagnose

pytestmark = pytest.mark.slow  # evaluates a trained run: see README


def test_diagnosis_holds_each_command_and_pays_per_second(evaluated_run, capsys):
    _, run_path, _ = evaluated_run
    assert diagnose.main([f"run_dir={run_path}", "units=2", "steps=60"]) == 0
    commands = pd.read_csv(run_path / "diagnosis" / "commands.csv")
    terms = pd.read_csv(run_path / "diagnosis" / "terms.csv", index_col="term")
    assert list(commands["command"]) == list(diagnose.COMMANDS) == list(terms.columns)
    np.testing.assert_allclose(commands[["u_x", "u_y", "u_yaw"]], list(diagnose.COMMANDS.values()))
    assert ((commands["alive_s"] > 0) & (commands["alive_s"] <= 60 * 0.02)).all()
    # per second of the steps each unit lived: the alive term is exactly its weight
    np.testing.assert_allclose(terms.loc["alive"], 0.15)
    np.testing.assert_allclose(terms.loc["total"], terms.drop("total").sum(), atol=1e-9)
    # the held command decides which terms pay: stand_still only when told to stand
    assert terms.loc["stand_still", "stand"] < 0
    assert (terms.loc["stand_still"].drop("stand") == 0).all()
    assert "reward per second" in capsys.readouterr().out


def test_diagnosis_usage_error(capsys):
    assert diagnose.main(["units=2"]) == 2
    assert "run_dir=" in capsys.readouterr().err


def test_diagnosis_on_a_terrain_cell_writes_beside_the_flat_one(evaluated_run, capsys):
    _, run_path, _ = evaluated_run
    assert diagnose.main([f"run_dir={run_path}", "cell=stairs-medium", "units=2", "steps=30"]) == 0
    out = run_path / "diagnosis" / "stairs-medium"
    terms = pd.read_csv(out / "terms.csv", index_col="term")
    assert list(terms.columns) == list(diagnose.COMMANDS)
    assert "(stairs-medium, deterministic policy)" in capsys.readouterr().out
    _, env = diagnose.diagnosis_env(run_path, 2, 30, diagnose.parse_cell("stairs-medium"))
    cfg = env.cfg.to_dict()
    assert (cfg["terrain"]["name"], cfg["difficulty"]["name"]) == ("stairs", "medium")


def test_diagnosis_names_the_allowed_cells(evaluated_run, capsys):
    _, run_path, _ = evaluated_run
    assert diagnose.main([f"run_dir={run_path}", "cell=stairs-steep"]) == 2
    assert "allowed: ['hard', 'medium']" in capsys.readouterr().err
