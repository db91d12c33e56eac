"""Session fixtures of the training-layer tests: one torch thread, a shared scene."""

from __future__ import annotations

import os
from collections.abc import Iterator

import pytest

from lca.config import set_torch_threads
from lca.sim.scene import Scene, build_scene

from .helpers import WANDB_KEYS, smoke_cfg


@pytest.fixture(scope="session", autouse=True)
def _one_torch_thread() -> None:
    set_torch_threads(1)


@pytest.fixture(scope="session")
def smoke_scene() -> Scene:
    """The scene of every `scale=smoke` config on the default (mixed) terrain."""
    return build_scene(smoke_cfg())


@pytest.fixture
def restore_wandb_env() -> Iterator[None]:
    """`train_run` sets WANDB_DIR / WANDB_RUN_GROUP with setdefault: start the test without
    them and put the process environment back afterwards."""
    saved = {k: os.environ.pop(k) for k in WANDB_KEYS if k in os.environ}
    yield
    for key in WANDB_KEYS:
        os.environ.pop(key, None)
    os.environ.update(saved)
