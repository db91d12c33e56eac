"""Builders shared by the training-layer tests (fixtures live in conftest.py).

Everything runs the real simulator and rsl-rl PPO at `scale=smoke` (8 envs, 8 steps per env,
2 iterations unless a test says otherwise) on one torch thread. In-process runs reuse one
compiled scene per terrain (building one takes ~1.5 s); CLI runs go through `run.py` in a
subprocess, with their run store under pytest's tmp_path.
"""

from __future__ import annotations

import csv
import sys
from pathlib import Path

from _cli import REPO, RUN_PY, SMOKE, cli_env, run_cli  # noqa: F401 (re-exported)
from omegaconf import DictConfig

from lca.config import compose
from lca.learn.trainer import Trainer
from lca.sim.scene import Scene
from lca.store import COMPLETE, RunDir
from lca.task.env import LocomotionEnv

WANDB_KEYS = ("WANDB_DIR", "WANDB_RUN_GROUP", "WANDB_MODE")
SWEEP_ARGS = ("-m", "actor=mlp,lstm", "scale=smoke", "logger=none", "torch_threads=1")


def smoke_cfg(*overrides: str) -> DictConfig:
    return compose([*SMOKE, *overrides])


def make_trainer(cfg: DictConfig, run_path: Path, scene: Scene) -> Trainer:
    return Trainer(cfg, RunDir(run_path), env=LocomotionEnv(cfg, scene=scene))


def read_curve(path: Path) -> list[dict]:
    with path.open(newline="") as f:
        return list(csv.DictReader(f))


def cli_command(*args: str) -> list[str]:
    return [sys.executable, str(RUN_PY), *args]


def complete_runs(runs_root: Path) -> list[Path]:
    return sorted(p.parent for p in runs_root.rglob(COMPLETE))
