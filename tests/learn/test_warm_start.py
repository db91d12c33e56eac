"""`algo.init_from`: a new run starts from another run's networks, at iteration 0, with its
own optimizer and schedules."""

from __future__ import annotations

import pytest
import torch

from lca.learn.train_cfg import build_train_cfg

from .helpers import make_trainer, read_curve, smoke_cfg


@pytest.mark.slow  # trains: see README
def test_warm_start_loads_networks_not_iteration(tmp_path, smoke_scene) -> None:
    donor = make_trainer(smoke_cfg("scale.max_iterations=3"), tmp_path / "donor", smoke_scene)
    donor.train()
    source = tmp_path / "donor" / "checkpoints" / "latest.pt"
    saved = torch.load(source, weights_only=False)
    assert saved["iter"] == 2

    cfg = smoke_cfg("scale.max_iterations=2", f"algo.init_from={source}")
    warm = make_trainer(cfg, tmp_path / "warm", smoke_scene)
    assert warm.start == 0
    for key, value in saved["actor_state_dict"].items():
        torch.testing.assert_close(warm.alg.actor.state_dict()[key], value, msg=key)
    for key, value in saved["critic_state_dict"].items():
        torch.testing.assert_close(warm.alg.critic.state_dict()[key], value, msg=key)
    fresh = make_trainer(smoke_cfg("scale.max_iterations=2"), tmp_path / "fresh", smoke_scene)
    weight = "mlp.0.weight"
    assert not torch.equal(fresh.alg.actor.state_dict()[weight], saved["actor_state_dict"][weight])

    warm.train()
    assert [r["iteration"] for r in read_curve(tmp_path / "warm" / "train_curve.csv")] == ["0", "1"]


def test_warm_start_from_missing_file_names_the_key(tmp_path, smoke_scene) -> None:
    cfg = smoke_cfg(f"algo.init_from={tmp_path / 'nothing.pt'}")
    with pytest.raises(FileNotFoundError, match="algo.init_from"):
        make_trainer(cfg, tmp_path / "run", smoke_scene)


def test_init_from_is_not_passed_to_ppo() -> None:
    algorithm = build_train_cfg(smoke_cfg("algo.init_from=x.pt"), "run")["algorithm"]
    assert "init_from" not in algorithm


@pytest.mark.slow  # trains: see README
def test_critic_warmup_trains_the_critic_only(tmp_path, smoke_scene) -> None:
    cfg = smoke_cfg("scale.max_iterations=4", "algo.critic_warmup=2")
    trainer = make_trainer(cfg, tmp_path / "run", smoke_scene)
    actor0 = {k: v.clone() for k, v in trainer.alg.actor.state_dict().items()}
    critic0 = {k: v.clone() for k, v in trainer.alg.critic.state_dict().items()}
    trainer.train(hook=lambda trainer, it, row: it == 1)  # stopped after the warm-up
    weight = "mlp.0.weight"
    assert torch.equal(trainer.alg.actor.state_dict()[weight], actor0[weight])
    assert not torch.equal(trainer.alg.critic.state_dict()[weight], critic0[weight])
    rates = [float(r["learning_rate"]) for r in read_curve(tmp_path / "run" / "train_curve.csv")]
    assert rates == [cfg.algo.learning_rate] * 2  # held: no KL to adapt it to

    resumed = make_trainer(cfg, tmp_path / "run", smoke_scene)
    resumed.train()
    assert not torch.equal(resumed.alg.actor.state_dict()[weight], actor0[weight])
    assert all(p.requires_grad for p in resumed.alg.actor.parameters())
