"""Perception curricula: when the actor's heightmap is on, and the two-stage switch in a real
training run (what the actor sees, and that networks and optimizer carry over)."""

from __future__ import annotations

import copy
import functools

import pytest
import torch

from lca.config import compose
from lca.learn import curriculum
from lca.sim.scene import build_scene

from .helpers import make_trainer, read_curve, smoke_cfg

pytestmark = pytest.mark.slow  # trains, evaluates or runs a stage: see README


@functools.cache
def _curriculum(name: str):
    return compose([f"curriculum={name}"]).curriculum


@pytest.mark.parametrize(
    ("name", "total", "switch"),
    [
        ("blind", 4, 4),
        ("one", 4, 0),
        ("two", 4, 2),
        ("two", 2, 1),
        ("two", 5, 3),  # ceil(2.5)
        ("two", 1, 1),  # a 1-iteration `two` run never turns perception on
    ],
)
def test_switch_iteration(name: str, total: int, switch: int) -> None:
    cfg = _curriculum(name)
    assert curriculum.switch_iteration(cfg, total) == switch
    stages = [curriculum.stage_name(cfg, it, total) for it in range(total)]
    assert stages == ["blind"] * switch + ["perception"] * (total - switch)
    assert [curriculum.perception_on(cfg, it, total) for it in range(total)] == [
        it >= switch for it in range(total)
    ]


# ---- two-stage run -----------------------------------------------------------------------

TOTAL = 4  # curriculum=two: iterations 0-1 blind, 2-3 with perception
SWITCH = 2


def _state(module: torch.nn.Module) -> dict[str, torch.Tensor]:
    return {k: v.detach().clone() for k, v in module.state_dict().items()}


@pytest.fixture(scope="module")
def two_stage(tmp_path_factory) -> dict:
    """A 4-iteration `curriculum=two` run on stairs whose spawn platform (0.5 m) is smaller
    than the actor's 1 m map, recording every observation `alg.act` receives, the actor and
    optimizer state after every update and at the first act of the perception stage."""
    cfg = smoke_cfg(
        "curriculum=two",
        f"scale.max_iterations={TOTAL}",
        "scale.checkpoint_interval=100",
        "terrain=stairs_up",
        "terrain.platform=0.5",
    )
    trainer = make_trainer(cfg, tmp_path_factory.mktemp("two_stage"), build_scene(cfg))
    alg = trainer.alg
    steps = int(cfg.algo.num_steps_per_env)
    rec: dict = {"height": [], "critic_height": [], "after_update": []}
    act, update = alg.act, alg.update

    def recording_act(obs):
        if len(rec["height"]) == SWITCH * steps:  # first act of iteration 2
            rec["actor_at_switch"] = _state(alg.actor)
            rec["critic_at_switch"] = _state(alg.critic)
            rec["optimizer_at_switch"] = copy.deepcopy(alg.optimizer.state_dict())
        rec["height"].append(obs["height"].clone())
        rec["critic_height"].append(obs["critic_height"].clone())
        return act(obs)

    def recording_update():
        losses = update()
        rec["after_update"].append(_state(alg.actor))
        return losses

    alg.act, alg.update = recording_act, recording_update
    rec["initial_actor"] = _state(alg.actor)
    trainer.train()
    rec["height"] = torch.stack(rec["height"]).reshape(TOTAL, steps, cfg.task.num_envs, -1)
    rec["critic_height"] = torch.stack(rec["critic_height"]).reshape(
        TOTAL, steps, cfg.task.num_envs, -1
    )
    rec["trainer"] = trainer
    rec["cfg"] = cfg
    return rec


def _load(trainer, name: str) -> dict:
    path = trainer.run.checkpoints / name
    return torch.load(path, weights_only=False, map_location="cpu")


def test_two_stage_curve_and_checkpoints(two_stage) -> None:
    trainer = two_stage["trainer"]
    rows = read_curve(trainer.run.curve)
    assert [r["stage"] for r in rows] == ["blind", "blind", "perception", "perception"]
    names = {p.name for p in trainer.run.checkpoints.iterdir()}
    assert names == {
        f"stage1_blind_it{SWITCH - 1}.pt",
        "final_perception.pt",
        "latest.pt",
    }
    stage1 = _load(trainer, f"stage1_blind_it{SWITCH - 1}.pt")
    assert stage1["iter"] == SWITCH - 1
    assert stage1["infos"] == {"stage": "blind", "penalty_scale": 1.0}


def test_actor_map_follows_stage_within_rollouts(two_stage) -> None:
    """From the second step of each iteration on: the map is exactly zero while blind and
    non-zero for every env with perception; the critic's map is on throughout."""
    height = two_stage["height"]
    assert torch.all(height[:SWITCH, 1:] == 0)
    assert torch.all(height[SWITCH:, 1:].abs().amax(dim=-1) > 0)
    assert torch.all(two_stage["critic_height"].abs().amax(dim=-1) > 0)


def test_actor_map_zero_on_every_blind_step(two_stage) -> None:
    height = two_stage["height"][:SWITCH]
    assert torch.all(height == 0), [
        (it, step) for it, step in (height != 0).any(-1).any(-1).nonzero().tolist()
    ]


def test_actor_map_on_at_every_perception_step(two_stage) -> None:
    height = two_stage["height"][SWITCH:]
    assert torch.all(height.abs().amax(dim=-1) > 0), (height.abs().amax(dim=-1) == 0).nonzero()


def test_networks_carry_over_the_switch(two_stage) -> None:
    """The actor the perception stage starts from is the one stage 1 ended with, and the one
    saved in the stage-1 checkpoint; the critic too."""
    trainer = two_stage["trainer"]
    stage1 = _load(trainer, f"stage1_blind_it{SWITCH - 1}.pt")
    at_switch = two_stage["actor_at_switch"]
    end_of_stage1 = two_stage["after_update"][SWITCH - 1]
    assert at_switch.keys() == stage1["actor_state_dict"].keys()
    for key, value in at_switch.items():
        assert torch.equal(value, end_of_stage1[key]), key
        assert torch.equal(value, stage1["actor_state_dict"][key]), key
    for key, value in two_stage["critic_at_switch"].items():
        assert torch.equal(value, stage1["critic_state_dict"][key]), key
    # stage 1 did train (else equality above is trivial), and stage 2 trained on from there
    initial = two_stage["initial_actor"]
    assert any(not torch.equal(initial[k], v) for k, v in at_switch.items())
    final = two_stage["after_update"][-1]
    assert any(not torch.equal(final[k], v) for k, v in at_switch.items())


def test_optimizer_state_carries_over_the_switch(two_stage) -> None:
    trainer, cfg = two_stage["trainer"], two_stage["cfg"]
    steps_per_update = int(cfg.algo.num_learning_epochs) * int(cfg.algo.num_mini_batches)
    saved = _load(trainer, f"stage1_blind_it{SWITCH - 1}.pt")["optimizer_state_dict"]
    live = two_stage["optimizer_at_switch"]
    assert saved["param_groups"] == live["param_groups"]
    assert saved["state"].keys() == live["state"].keys() and saved["state"]
    for idx, state in live["state"].items():
        assert float(state["step"]) == SWITCH * steps_per_update
        for key in ("exp_avg", "exp_avg_sq"):
            assert torch.equal(state[key], saved["state"][idx][key]), (idx, key)
    # Adam's step count runs on through stage 2: the optimizer was not re-created
    final = _load(trainer, "final_perception.pt")["optimizer_state_dict"]
    assert {float(s["step"]) for s in final["state"].values()} == {TOTAL * steps_per_update}
