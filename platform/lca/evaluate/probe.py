"""Evaluation during training: the paper's protocol on one cell, every few minutes.

The probe owns its environment and random streams, evaluates a copy of the training actor
(the trainer's modules, hidden states and modes are untouched) and appends one row per
evaluation to `<run>/probe_evals.csv`. Every evaluation is seeded alike, so successive rows
differ only by the policy.
"""

from __future__ import annotations

import copy
import csv
import math
import time
from pathlib import Path

import numpy as np
import torch
from omegaconf import DictConfig, OmegaConf

from lca.evaluate.config import EvalCell
from lca.evaluate.policy import new_policy
from lca.evaluate.protocol import cell_config, round_seed, run_round
from lca.task.env import LocomotionEnv

PROBE_FIELDS = (
    "iteration",
    "env_steps",
    "train_wall_s",
    "penalty_scale",
    "paper_objective",
    "success",
    "track_cm_s",
    "still_cm_s",
    "stairs_success",
    "uneven_success",
    "contacts_per_step",
    "mean_steps",
    "eval_s",
    "units",
    "confirm",  # 1: a larger evaluation confirming the probe of the same iteration
)


class TrainingProbe:
    def __init__(
        self,
        cfg: DictConfig,
        out: Path | None,
        cell: EvalCell,
        units: int,
        steps: int,
        train_cfg: dict,
        command_x: list[float] | None = None,
    ):
        """`out`: the CSV that `record` appends to (None: a probe that only evaluates);
        `train_cfg`: the rsl-rl runner config of the training (the networks to copy into);
        `command_x`: forward commands (m/s) instead of the protocol's `eval.command_x`."""
        cfg = copy.deepcopy(cfg)
        cfg.eval.units, cfg.eval.steps = int(units), int(steps)
        if command_x is not None:
            cfg.eval.command_x = list(command_x)
        self.cell = OmegaConf.structured(cell)
        self.env = LocomotionEnv(cell_config(cfg, self.cell))
        self.env.set_perception(False)
        self.policy = new_policy(cfg, self.env, train_cfg)
        self.seed = int(cfg.eval.seed)
        self.steps = int(steps)
        self.units = int(units)
        self.out = Path(out) if out is not None else None

    @staticmethod
    def read(path: Path) -> list[dict]:
        """The rows recorded so far (none if the file does not exist)."""
        if not Path(path).exists():
            return []
        with Path(path).open(newline="") as f:
            return [
                {k: float(v) if v != "" else math.nan for k, v in r.items()}
                for r in csv.DictReader(f)
            ]

    def evaluate(self, actor: torch.nn.Module, perception: bool = False) -> dict:
        """Success (%), tracking error (cm/s) and contacts per step (%) over the units."""
        t0 = time.perf_counter()
        self.policy.load_state_dict(actor.state_dict())
        self.env.set_perception(perception)
        with torch.random.fork_rng(devices=[]):
            self.env.reseed(round_seed(self.seed, self.cell, 0))
            result = run_round(self.env, self.policy, self.steps)
        return {
            "success": float(np.mean(result["success"])),
            "track_cm_s": float(np.mean(result["track_cm_s"])),
            "contacts_per_step": float(np.mean(result["contacts_per_step"])),
            "mean_steps": float(np.mean(result["steps"])),
            "eval_s": round(time.perf_counter() - t0, 2),
            "units": self.units,
        }

    def record(self, row: dict) -> None:
        new = not self.out.exists()
        with self.out.open("a", newline="") as f:
            writer = csv.DictWriter(f, fieldnames=PROBE_FIELDS, extrasaction="ignore")
            if new:
                writer.writeheader()
            writer.writerow(row)
