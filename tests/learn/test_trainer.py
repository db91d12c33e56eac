"""Trainer and train_run in-process: every architecture x curriculum trains, a run's training
summary, resuming, and logging to wandb offline."""

from __future__ import annotations

import contextlib
import io
import json
import math
import os
from pathlib import Path

import pytest
import torch

from lca.learn.run import train_run
from lca.learn.train_cfg import build_train_cfg
from lca.store import RunDir

from .helpers import WANDB_KEYS, make_trainer, read_curve, smoke_cfg

pytestmark = pytest.mark.slow  # trains, evaluates or runs a stage: see README

# Stage of iterations 0 and 1 of a 2-iteration run (`two` switches at ceil(0.5 * 2) = 1).
STAGES = {
    "blind": ["blind", "blind"],
    "one": ["perception", "perception"],
    "two": ["blind", "perception"],
}
FINITE_COLUMNS = (
    "steps_per_s",
    "collect_s",
    "update_s",
    "value_loss",
    "surrogate_loss",
    "action_std",
)


def _assert_architecture(state: dict, actor: str | None, encoder: str) -> None:
    has_rnn = "rnn.rnn.weight_ih_l0" in state
    if actor is not None:
        assert has_rnn == (actor == "lstm"), sorted(state)
    first = next(v for k, v in state.items() if k.startswith("encoder.net.") and "weight" in k)
    assert first.dim() == (4 if encoder == "cnn" else 2), first.shape
    assert all(torch.isfinite(v).all() for v in state.values() if v.is_floating_point())


@pytest.mark.parametrize("curriculum", ["blind", "one", "two"])
@pytest.mark.parametrize("encoder", ["cnn", "mlp"])
@pytest.mark.parametrize("actor", ["mlp", "lstm"])
def test_combination_trains(actor, encoder, curriculum, smoke_scene, tmp_path) -> None:
    cfg = smoke_cfg(f"actor={actor}", f"encoder={encoder}", f"curriculum={curriculum}")
    trainer = make_trainer(cfg, tmp_path / "run", smoke_scene)
    last = trainer.train()

    assert last["iteration"] == 1
    assert last["env_steps"] == 2 * 8 * 8
    assert last["stage"] == STAGES[curriculum][-1]
    for key in FINITE_COLUMNS:
        assert math.isfinite(last[key]), (key, last[key])
    assert last["action_std"] > 0
    # No episode ends within 16 steps: the episode columns are NaN then, never infinite.
    assert not any(math.isinf(v) for v in last.values() if isinstance(v, float))

    rows = read_curve(trainer.run.curve)
    assert [int(r["iteration"]) for r in rows] == [0, 1]
    assert [r["stage"] for r in rows] == STAGES[curriculum]
    assert float(rows[-1]["value_loss"]) == pytest.approx(last["value_loss"])

    ckpts = trainer.run.checkpoints
    expected = {"latest.pt", "previous.pt", f"final_{STAGES[curriculum][-1]}.pt"}
    if curriculum == "two":
        expected.add("stage1_blind_it0.pt")
    assert {p.name for p in ckpts.iterdir()} == expected
    saved = torch.load(ckpts / "latest.pt", weights_only=False, map_location="cpu")
    assert saved["iter"] == 1
    assert saved["infos"] == {"stage": STAGES[curriculum][-1], "penalty_scale": 1.0}
    _assert_architecture(saved["actor_state_dict"], actor, encoder)
    _assert_architecture(saved["critic_state_dict"], None, encoder)
    # what evaluation rebuilds the networks from
    written = json.loads((trainer.run.path / "train_cfg.json").read_text())
    assert written == build_train_cfg(cfg, trainer.run.path.name)
    assert "rnn.rnn.weight_ih_l0" not in saved["critic_state_dict"]
    # the checkpoint holds the weights the trainer ended with
    policy = trainer.alg.get_policy().state_dict()
    assert all(torch.equal(policy[k], v) for k, v in saved["actor_state_dict"].items())


# ---- train_run: a fresh run, and a run interrupted after its last checkpoint ----------------


@pytest.fixture(scope="module")
def two_runs(tmp_path_factory, smoke_scene) -> dict:
    """Two `train_run` calls in one process (as a basic-launcher sweep makes them):

    `resumed`: a Trainer trained all 2 iterations and wrote its final `latest.pt`, then the job
    died before COMPLETE (e.g. during the export); train_run picks it up.
    `fresh`: a new run (seed 3).
    """
    root = tmp_path_factory.mktemp("train_run")
    saved_env = {k: os.environ.pop(k) for k in WANDB_KEYS if k in os.environ}
    out: dict = {}
    try:
        resumed, fresh = root / "resumed", root / "fresh"
        make_trainer(smoke_cfg(), resumed, smoke_scene).train()
        out["pre_curve"] = read_curve(RunDir(resumed).curve)
        for name, path, cfg in (
            ("resumed", resumed, smoke_cfg()),
            ("fresh", fresh, smoke_cfg("seed=3")),
        ):
            buf = io.StringIO()
            with contextlib.redirect_stdout(buf):
                summary = train_run(cfg, RunDir(path))
            out[name] = {
                "path": path,
                "summary": summary,
                "stdout": buf.getvalue(),
                "wandb_dir": os.environ.get("WANDB_DIR"),
            }
    finally:
        for key in WANDB_KEYS:
            os.environ.pop(key, None)
        os.environ.update(saved_env)
    return out


def test_fresh_run_summary(two_runs) -> None:
    run = two_runs["fresh"]
    path: Path = run["path"]
    summary = run["summary"]
    json.dumps(summary, allow_nan=False)  # NaN (no finished episode) is stored as None
    assert summary["iterations"] == 2
    final = summary["final"]
    last_row = read_curve(path / "train_curve.csv")[-1]
    assert final["iteration"] == int(last_row["iteration"]) == 1
    assert final["value_loss"] == pytest.approx(float(last_row["value_loss"]))
    assert set(summary["exported"]) == {"onnx", "torchscript"}
    for rel in summary["exported"].values():
        assert (path / rel).is_file()
    saved = torch.load(path / "checkpoints" / "latest.pt", weights_only=False, map_location="cpu")
    assert saved["iter"] == 1
    assert "resuming" not in run["stdout"]


def test_run_interrupted_after_last_checkpoint_resumes_without_training(two_runs) -> None:
    run = two_runs["resumed"]
    path: Path = run["path"]
    assert "resuming resumed at iteration 2/2" in run["stdout"]
    assert "[lca] it" not in run["stdout"]  # nothing left to train
    assert (path / "exported" / "policy.onnx").is_file()
    assert read_curve(path / "train_curve.csv") == two_runs["pre_curve"]


def test_run_interrupted_after_last_checkpoint_keeps_final_row(two_runs) -> None:
    final = two_runs["resumed"]["summary"]["final"]
    assert final.get("iteration") == 1
    assert final.get("value_loss") == pytest.approx(float(two_runs["pre_curve"][-1]["value_loss"]))


def test_each_run_sets_its_own_wandb_dir(two_runs) -> None:
    assert two_runs["resumed"]["wandb_dir"] == str(two_runs["resumed"]["path"])
    assert two_runs["fresh"]["wandb_dir"] == str(two_runs["fresh"]["path"])


# ---- wandb ----------------------------------------------------------------------------------


def test_wandb_offline_run(tmp_path, monkeypatch, restore_wandb_env) -> None:
    wandb = pytest.importorskip("wandb")
    monkeypatch.setenv("WANDB_MODE", "offline")
    path = tmp_path / "wandb_run"
    try:
        train_run(smoke_cfg("logger=wandb"), RunDir(path))
        finished = wandb.run is None
    finally:
        if wandb.run is not None:  # do not leave a run open for the rest of the session
            wandb.finish()
    assert finished, "wandb.finish was not called"
    assert [int(r["iteration"]) for r in read_curve(path / "train_curve.csv")] == [0, 1]
    runs = sorted((path / "wandb").glob("offline-run-*"))
    assert len(runs) == 1, runs
    assert list(runs[0].glob("run-*.wandb")), list(runs[0].iterdir())
    # the final checkpoint reaches wandb under its final name, as a readable file
    files = runs[0] / "files"
    saved = [p for p in files.rglob("*.pt")]
    assert any(p.name.startswith("final_") for p in saved), list(files.rglob("*"))
    for p in saved:
        assert not p.name.endswith(".tmp")
        assert p.resolve().is_file(), f"{p} is a broken link"
