"""Evaluation during training: it writes one row per call and leaves training untouched
(same weights and curve as a run without it: its random streams are its own)."""

from __future__ import annotations

import csv
from pathlib import Path

import pytest
import torch

from lca.evaluate.config import EvalCell
from lca.evaluate.probe import PROBE_FIELDS, TrainingProbe
from lca.learn.train_cfg import build_train_cfg
from lca.learn.trainer import Trainer
from lca.sim.scene import Scene, build_scene
from lca.store import RunDir
from lca.task.env import LocomotionEnv

from .helpers import smoke_cfg

pytestmark = pytest.mark.slow  # trains, evaluates or runs a stage: see README


def make_trainer(cfg, run_path, scene) -> Trainer:
    return Trainer(cfg, RunDir(run_path), env=LocomotionEnv(cfg, scene=scene))


def read_curve(path) -> list[dict]:
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


TRAINED = ("mean_reward", "value_loss", "surrogate_loss", "action_std", "kl")


@pytest.fixture(scope="module")
def smoke_scene() -> Scene:
    return build_scene(smoke_cfg())


def _train(tmp_path, scene, name: str, probe: TrainingProbe | None):
    cfg = smoke_cfg("scale.max_iterations=3", "seed=3")
    trainer = make_trainer(cfg, tmp_path / name, scene)

    def hook(trainer, it, row):
        result = probe.evaluate(trainer.alg.get_policy())
        probe.record({"iteration": it, "env_steps": row["env_steps"], **result})
        return False

    trainer.train(hook=hook if probe else None)
    return trainer


def test_probe_rows_and_untouched_training(tmp_path, smoke_scene):
    cfg = smoke_cfg("scale.max_iterations=3", "seed=3")
    probe = TrainingProbe(
        cfg, tmp_path / "probe.csv", EvalCell("flat", "medium"), 3, 30, build_train_cfg(cfg, "p")
    )
    with_probe = _train(tmp_path, smoke_scene, "with", probe)
    without = _train(tmp_path, smoke_scene, "without", None)

    rows = TrainingProbe.read(tmp_path / "probe.csv")
    assert [int(r["iteration"]) for r in rows] == [0, 1, 2]
    assert set(rows[0]) == set(PROBE_FIELDS)
    assert all(0 <= r["success"] <= 100 and r["track_cm_s"] >= 0 for r in rows)
    assert all(r["mean_steps"] > 0 for r in rows)

    a = with_probe.alg.get_policy().state_dict()
    b = without.alg.get_policy().state_dict()
    for key in a:
        torch.testing.assert_close(a[key], b[key], rtol=0, atol=0, msg=key)
    curve_a = read_curve(tmp_path / "with" / "train_curve.csv")
    curve_b = read_curve(tmp_path / "without" / "train_curve.csv")
    for ra, rb in zip(curve_a, curve_b, strict=True):
        assert [ra[k] for k in TRAINED] == [rb[k] for k in TRAINED]


def test_probe_is_repeatable(tmp_path, smoke_scene):
    cfg = smoke_cfg("seed=3")
    trainer = make_trainer(cfg, tmp_path / "run", smoke_scene)
    probe = TrainingProbe(
        cfg, tmp_path / "p.csv", EvalCell("flat", "medium"), 3, 30, build_train_cfg(cfg, "p")
    )
    actor = trainer.alg.get_policy()
    first, second = probe.evaluate(actor), probe.evaluate(actor)
    first.pop("eval_s"), second.pop("eval_s")
    assert first == second


def test_probe_command_override_sets_the_commands():
    cfg = smoke_cfg()
    cell = EvalCell("flat", "medium")
    still = TrainingProbe(cfg, None, cell, 2, 5, build_train_cfg(cfg, "p"), [0, 0])
    assert list(still.env.task_cfg.commands.lin_vel_x) == [0.0, 0.0]
    forward = TrainingProbe(cfg, Path("unused.csv"), cell, 2, 5, build_train_cfg(cfg, "p"))
    assert list(forward.env.task_cfg.commands.lin_vel_x) == list(cfg.eval.command_x)
