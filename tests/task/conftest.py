"""Builders shared by the task-layer tests.

Environments are stateful, so each test module builds its own (module-scoped fixtures);
building one takes ~2 s on a 2-core CPU.
"""

from __future__ import annotations

from collections.abc import Callable

import pytest
from omegaconf import DictConfig

from lca.config import compose
from lca.task.env import LocomotionEnv

# 30 Hz PD gains: the robot stands passively (the 10 Hz training gains need a policy).
STAND = ["scale=smoke", "terrain=flat", "robot.natural_frequency_hz=30"]
MIXED = ["scale=smoke", "task.num_envs=8", "terrain=mixed"]


@pytest.fixture(scope="session")
def make_env() -> Callable[..., tuple[DictConfig, LocomotionEnv]]:
    def build(*overrides: str) -> tuple[DictConfig, LocomotionEnv]:
        cfg = compose(list(overrides))
        return cfg, LocomotionEnv(cfg)

    return build
