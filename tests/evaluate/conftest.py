"""Session fixtures of the evaluation-layer tests: one torch thread, one tiny trained run
(2 PPO iterations at scale=smoke) and its in-process evaluation."""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import pytest
from omegaconf import DictConfig

from lca.config import set_torch_threads
from lca.evaluate.run import evaluate_and_write

from .helpers import train_tiny_run


@pytest.fixture(scope="session", autouse=True)
def _one_torch_thread() -> None:
    set_torch_threads(1)


@pytest.fixture(scope="session")
def evaluated_run(tmp_path_factory) -> tuple[DictConfig, Path, pd.DataFrame]:
    """(config, run dir, summary) of a trained run evaluated with `evaluate_and_write`.
    Tests that change the run work on a copy."""
    cfg, run = train_tiny_run(tmp_path_factory.mktemp("evaluate") / "tiny_run")
    summary = evaluate_and_write(run.path, log=None)
    return cfg, run.path, summary
