"""Builders shared by the evaluation-layer tests (fixtures live in conftest.py).

Runs are trained with the real simulator and rsl-rl PPO at `scale=smoke` (8 envs, 2
iterations) on one torch and one mjbatch thread, and evaluated with tiny sizes
(EVAL: 4 units x 2 episodes x 20 steps on the 4 default cells). CLI calls go through
`python -m lca.evaluate` in a subprocess.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pandas as pd
from _cli import CONF, REPO, SMOKE, cli_env, run_module  # noqa: F401 (re-exported)
from omegaconf import DictConfig

from lca.config import compose
from lca.evaluate.protocol import cell_name
from lca.learn.trainer import Trainer
from lca.store import RunDir

UNITS, EPISODES, STEPS = 4, 2, 20
EVAL = [f"eval.units={UNITS}", f"eval.episodes={EPISODES}", f"eval.steps={STEPS}"]
POLICY_DT = 0.02  # s: 200 Hz physics, decimation 4


def smoke_cfg(*overrides: str) -> DictConfig:
    return compose([*SMOKE, *EVAL, *overrides])


def train_tiny_run(run_path: Path, *overrides: str) -> tuple[DictConfig, RunDir]:
    """A real 2-iteration PPO run with its config.yaml / provenance.json and final checkpoint."""
    cfg = smoke_cfg(*overrides)
    run = RunDir(run_path)
    run.path.mkdir(parents=True, exist_ok=True)
    run.write_provenance(cfg, [*SMOKE, *EVAL, *overrides], {})
    Trainer(cfg, run).train()
    return cfg, run


def episode_files(run_dir: Path, cfg: DictConfig) -> list[Path]:
    """Every per-round file the protocol must write, in (cell, episode) order."""
    return [
        Path(run_dir) / "eval" / cell_name(cell) / f"episode_{e}.csv"
        for cell in cfg.eval.cells
        for e in range(cfg.eval.episodes)
    ]


def evaluate_command(run_dir: Path, *overrides: str) -> list[str]:
    return [sys.executable, "-m", "lca.evaluate", f"run_dir={run_dir}", *overrides]


def run_evaluate_cli(
    run_dir: Path, *overrides: str, cwd: Path, timeout: float = 120
) -> subprocess.CompletedProcess:
    """`python -m lca.evaluate run_dir=<dir> [overrides]` from `cwd`."""
    return run_module(*evaluate_command(run_dir, *overrides)[2:], cwd=cwd, timeout=timeout)


def sort_episodes(frame: pd.DataFrame) -> pd.DataFrame:
    keys = ["cell_terrain", "cell_difficulty", "episode", "unit"]
    return frame.sort_values(keys).reset_index(drop=True)
