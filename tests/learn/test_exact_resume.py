"""A run stopped at an iteration boundary and resumed by a new process (a new Trainer on the
same run directory) continues exactly as the uninterrupted run: same curve, same weights."""

from __future__ import annotations

import pytest
import torch

from .helpers import make_trainer, read_curve, smoke_cfg

pytestmark = pytest.mark.slow  # trains, evaluates or runs a stage: see README

TRAINED = ("mean_reward", "mean_episode_length", "value_loss", "surrogate_loss", "action_std")


@pytest.mark.parametrize("actor", ["mlp", "lstm"])
def test_resumed_run_equals_uninterrupted_run(tmp_path, smoke_scene, actor):
    overrides = (
        "scale.max_iterations=5",
        "scale.checkpoint_interval=1",
        f"actor={actor}",
        "task.reward_curriculum.enabled=true",
        "task.randomization.push_interval_s=0.1",  # pushes, frictions and resets all happen
    )
    straight = make_trainer(smoke_cfg(*overrides), tmp_path / "straight", smoke_scene)
    straight.train()

    first = make_trainer(smoke_cfg(*overrides), tmp_path / "resumed", smoke_scene)
    first.train(hook=lambda trainer, it, row: it == 2)  # "killed" after iteration 2
    resumed = make_trainer(smoke_cfg(*overrides), tmp_path / "resumed", smoke_scene)
    assert resumed.start == 3
    resumed.train()

    a = read_curve(tmp_path / "straight" / "train_curve.csv")
    b = read_curve(tmp_path / "resumed" / "train_curve.csv")
    assert [r["iteration"] for r in b] == [str(i) for i in range(5)]
    for ra, rb in zip(a, b, strict=True):
        assert {k: ra[k] for k in TRAINED} == {k: rb[k] for k in TRAINED}, ra["iteration"]
    wa = straight.alg.get_policy().state_dict()
    wb = resumed.alg.get_policy().state_dict()
    for key in wa:
        torch.testing.assert_close(wa[key], wb[key], rtol=0, atol=0, msg=key)
