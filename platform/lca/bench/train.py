"""PPO iteration wall time split into collection (env + policy inference) and update, at
`scale=cpu` by default, in a throwaway run directory."""

from __future__ import annotations

import csv
import tempfile
from collections.abc import Callable
from pathlib import Path

import numpy as np

from lca.config import compose, set_torch_threads
from lca.learn.trainer import Trainer
from lca.store import RunDir

WARMUP = 1
ITERATIONS = 6


BASELINE = ["algo.num_learning_epochs=5", "algo.num_mini_batches=4"]  # rsl-rl's PPO defaults


def run(overrides: list[str], log: Callable[[str], None] | None = print) -> dict:
    """The configured run, and as a baseline the same run with rsl-rl's default PPO epochs."""
    result = measure(overrides, log)
    result["baseline"] = measure([*overrides, *BASELINE], log)
    result["baseline_overrides"] = BASELINE
    return result


def measure(overrides: list[str], log: Callable[[str], None] | None = print) -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        cfg = compose(["logger=none", f"scale.max_iterations={WARMUP + ITERATIONS}", *overrides])
        cfg.scale.log_interval = 10**9
        set_torch_threads(int(cfg.torch_threads))
        trainer = Trainer(cfg, RunDir(Path(tmp) / "bench"))
        trainer.train()
        with trainer.run.curve.open() as f:
            rows = list(csv.DictReader(f))[WARMUP:]
    collect = np.array([float(r["collect_s"]) for r in rows])
    update = np.array([float(r["update_s"]) for r in rows])
    samples = cfg.algo.num_steps_per_env * cfg.task.num_envs
    result = {
        "backend": cfg.sim.backend,
        "num_envs": int(cfg.task.num_envs),
        "steps_per_env": int(cfg.algo.num_steps_per_env),
        "learning_epochs": int(cfg.algo.num_learning_epochs),
        "actor": cfg.actor.name,
        "encoder": cfg.encoder.name,
        "torch_threads": int(cfg.torch_threads),
        "iterations": len(rows),
        "collect_s": float(np.median(collect)),
        "update_s": float(np.median(update)),
        "iteration_s": float(np.median(collect + update)),
        "update_fraction": float(np.median(update / (collect + update))),
        "steps_per_s": float(samples / np.median(collect + update)),
        "collect_steps_per_s": float(samples / np.median(collect)),
    }
    if log:
        log(f"median of {len(rows)} iterations after {WARMUP} warm-up")
    return result


def table(r: dict) -> str:
    verdict = "meets" if r["update_fraction"] <= 0.25 else "MISSES"
    lines = [_describe(r), "baseline (" + " ".join(r["baseline_overrides"]) + "):"]
    lines += ["  " + line for line in _describe(r["baseline"]).splitlines()]
    lines.append(
        f"target: update <= 25 % of an iteration: {100 * r['update_fraction']:.1f} % "
        f"({verdict}); baseline {100 * r['baseline']['update_fraction']:.1f} %; "
        f"iteration {r['baseline']['iteration_s'] / r['iteration_s']:.2f}x faster"
    )
    return "\n".join(lines)


def _describe(r: dict) -> str:
    return "\n".join(
        [
            f"N={r['num_envs']} x {r['steps_per_env']} steps, {r['learning_epochs']} epochs, "
            f"actor={r['actor']}, encoder={r['encoder']}, torch_threads={r['torch_threads']}",
            f"iteration {r['iteration_s']:.2f} s = collect {r['collect_s']:.2f} s + "
            f"update {r['update_s']:.2f} s",
            f"steps/s {r['steps_per_s']:,.0f} (collection alone {r['collect_steps_per_s']:,.0f})",
        ]
    )
