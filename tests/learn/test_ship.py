"""`python -m lca.ship`: a run copied small, and an unfinished one shipped to be resumed."""

from __future__ import annotations

import pandas as pd
import pytest
import torch

from lca import ship

from .helpers import make_trainer, read_curve, smoke_cfg

pytestmark = pytest.mark.slow  # trains: see README


@pytest.fixture
def unfinished(tmp_path, smoke_scene):
    cfg = smoke_cfg("scale.max_iterations=5", "scale.checkpoint_interval=1")
    trainer = make_trainer(cfg, tmp_path / "run", smoke_scene)
    trainer.run.write_provenance(cfg, [], {})
    trainer.train(hook=lambda trainer, it, row: it == 2)  # stopped after iteration 2
    return cfg, tmp_path / "run"


def test_resumable_ship_is_networks_only_and_resumes_at_its_iteration(
    unfinished, tmp_path, smoke_scene
):
    cfg, run = unfinished
    files = ship.ship(run, tmp_path / "shipped", resumable=True)
    latest = tmp_path / "shipped" / "checkpoints" / "latest.pt"
    assert latest in files and (tmp_path / "shipped" / "config.yaml") in files
    saved = torch.load(latest, weights_only=False)
    assert not set(ship.DROPPED_KEYS) & set(saved) and saved["iter"] == 2
    whole = run / "checkpoints" / "latest.pt"
    assert latest.stat().st_size < whole.stat().st_size / 2

    rate = torch.load(run / "checkpoints" / "latest.pt", weights_only=False)[
        "optimizer_state_dict"
    ]["param_groups"][0]["lr"]
    assert saved["infos"]["learning_rate"] == rate

    resumed = make_trainer(cfg, tmp_path / "shipped", smoke_scene)
    assert resumed.start == 3
    # networks only: a fresh optimizer and fresh environments, and provenance says so
    resume = resumed.run.provenance()["resumed"]
    assert resume == {"iteration": 3, "from": "latest.pt", "exact": False}
    assert resumed.alg.learning_rate == rate  # the run's adapted rate, not the configured one
    weight = "mlp.0.weight"
    torch.testing.assert_close(
        resumed.alg.actor.state_dict()[weight], saved["actor_state_dict"][weight]
    )
    resumed.train()
    assert [r["iteration"] for r in read_curve(tmp_path / "shipped" / "train_curve.csv")] == [
        str(i) for i in range(5)
    ]


def test_exact_ship_keeps_the_whole_checkpoint(unfinished, tmp_path):
    _, run = unfinished
    ship.ship(run, tmp_path / "exact", resumable=True, exact=True)
    saved = torch.load(tmp_path / "exact" / "checkpoints" / "latest.pt", weights_only=False)
    assert set(ship.DROPPED_KEYS) <= set(saved)
    # the curve ships at 6 significant digits, every row and column kept
    source, shipped = (pd.read_csv(d / ship.CURVE) for d in (run, tmp_path / "exact"))
    pd.testing.assert_frame_equal(shipped, source, check_dtype=False, rtol=1e-5)


def test_exact_needs_resumable(tmp_path):
    with pytest.raises(SystemExit):
        ship.main([str(tmp_path), str(tmp_path / "out"), "--exact"])
