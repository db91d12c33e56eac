"""A blind policy is tested blind: every observation its actor receives in the evaluation
protocol and in the hardware-style trials carries an all-zero heightmap, while a two-stage
policy's carries the terrain. Checked with a spy wrapped around the policy under test."""

from __future__ import annotations

import pytest

from lca.evaluate import hardware, protocol
from lca.evaluate.policy import load_run_config

from .helpers import train_tiny_run

pytestmark = pytest.mark.slow  # trains two tiny runs and evaluates them
# the stairs start 0.3 m ahead, inside the 1 m map, so a seeing policy sees them at once
HARDWARE = [
    "hardware.trials=2",
    "hardware.time_limit_s=0.2",
    "hardware.tasks=[stair_ascent]",
    "hardware.approach=0.3",
]


def spied(load, seen: list[float]):
    def load_and_spy(*args, **kwargs):
        policy = load(*args, **kwargs)

        class Spy:
            def __call__(self, obs):
                seen.append(float(obs["height"].abs().max()))
                return policy(obs)

            def reset(self, dones):
                policy.reset(dones)

        return Spy()

    return load_and_spy


def map_seen(tmp_path, monkeypatch, curriculum: str) -> tuple[list[float], list[float]]:
    _, run = train_tiny_run(tmp_path / curriculum, f"curriculum={curriculum}")
    cfg = load_run_config(run.path, HARDWARE)
    in_eval, in_trials = [], []
    monkeypatch.setattr(protocol, "load_policy", spied(protocol.load_policy, in_eval))
    monkeypatch.setattr(hardware, "load_policy", spied(hardware.load_policy, in_trials))
    protocol.evaluate_run(run.path, cfg, log=None)
    hardware.run_hardware(run.path, cfg, log=None)
    assert in_eval and in_trials
    return in_eval, in_trials


def test_a_blind_policy_sees_a_zero_map(tmp_path, monkeypatch) -> None:
    in_eval, in_trials = map_seen(tmp_path, monkeypatch, "blind")
    assert max(in_eval) == 0.0 and max(in_trials) == 0.0


def test_a_two_stage_policy_sees_the_terrain(tmp_path, monkeypatch) -> None:
    in_eval, in_trials = map_seen(tmp_path, monkeypatch, "two")
    assert max(in_eval) > 0.0 and max(in_trials) > 0.0
