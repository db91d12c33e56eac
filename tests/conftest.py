"""Shared, session-scoped configs and scenes: building a scene takes ~0.5-2 s.

LCA_TEST_REVERSE=1 runs the collected tests in reverse order: with `-p randomly` (shuffled),
the check that no test depends on another having run first."""

from __future__ import annotations

import os

import pytest
from omegaconf import DictConfig

from lca.config import compose
from lca.sim.scene import Scene, build_scene

# 30 Hz PD instead of the 10 Hz training gains: a passive stand of a 33 kg humanoid whose CoM
# is ~0.67 m above the ankles needs ankle stiffness above m*g*h (~220 N m/rad); the 10 Hz
# gains (ankle kp 28.5) rely on the policy for balance, so the robot falls without one.
STAND_OVERRIDES = ["terrain=flat", "scale=smoke", "robot.natural_frequency_hz=30"]
MIXED_OVERRIDES = ["terrain=mixed", "scale=smoke"]


def pytest_collection_modifyitems(config, items) -> None:
    if os.environ.get("LCA_TEST_REVERSE") == "1":
        items.reverse()


@pytest.fixture(scope="session")
def flat_cfg() -> DictConfig:
    return compose(STAND_OVERRIDES)


@pytest.fixture(scope="session")
def flat_scene(flat_cfg: DictConfig) -> Scene:
    return build_scene(flat_cfg)


@pytest.fixture(scope="session")
def mixed_cfg() -> DictConfig:
    return compose(MIXED_OVERRIDES)


@pytest.fixture(scope="session")
def mixed_scene(mixed_cfg: DictConfig) -> Scene:
    return build_scene(mixed_cfg)
