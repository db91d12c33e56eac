"""PPO iteration wall time, at `scale=cpu` by default, in a throwaway run directory, split into
physics (the sim's steps), the task (observations, rewards, maps, resets, rollout storage),
policy inference and the PPO update. In the same run: the same command on flat ground (the
plane), with rsl-rl's default PPO epochs, and raw physics on the plane at the same number of
envs and threads (the physical limit of training on this machine)."""

from __future__ import annotations

import csv
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

from lca.bench.sim import batched_rate
from lca.config import compose, set_torch_threads
from lca.learn.trainer import Trainer
from lca.sim.scene import build_scene
from lca.store import RunDir

WARMUP = 1
ITERATIONS = 6
TERRAIN_TARGET = 0.8  # issue 27: the mixed terrain trains at >= 0.8x the plane's rate

BASELINE = ["algo.num_learning_epochs=5", "algo.num_mini_batches=4"]  # rsl-rl's PPO defaults
FLAT = ["terrain=flat"]


def run(overrides: list[str], log: Callable[[str], None] | None = print) -> dict:
    """The configured run, the same on flat ground, and with rsl-rl's default PPO epochs."""
    result = measure(overrides, log)
    if result["terrain"] != "flat":
        result["flat"] = measure([*overrides, *FLAT], log)
    result["baseline"] = measure([*overrides, *BASELINE], log)
    result["baseline_overrides"] = BASELINE
    result["plane_physics_env_steps_per_s"] = plane_physics(overrides)
    return result


def plane_physics(overrides: list[str]) -> float:
    """Env steps/s of bare physics on the plane (PD holding home), at the run's envs/threads."""
    cfg = compose([*overrides, *FLAT])
    scene = build_scene(cfg)
    decimation = int(cfg.sim.decimation)
    rate = batched_rate(scene, cfg.sim, int(cfg.task.num_envs), cfg.sim.num_threads, decimation)
    return rate / decimation


class _Timed:
    """Wraps a callable and adds its wall time to `seconds` (the bench's split)."""

    def __init__(self, fn: Callable) -> None:
        self.fn, self.seconds = fn, 0.0

    def __call__(self, *args, **kwargs):
        t0 = time.perf_counter()
        try:
            return self.fn(*args, **kwargs)
        finally:
            self.seconds += time.perf_counter() - t0


def measure(overrides: list[str], log: Callable[[str], None] | None = print) -> dict:
    physics_s, inference_s = [], []

    def split(trainer: Trainer, iteration: int, row: dict) -> bool:
        physics_s.append(trainer.env.sim.step.seconds)
        inference_s.append(trainer.alg.act.seconds)
        trainer.env.sim.step.seconds = trainer.alg.act.seconds = 0.0
        return False

    with tempfile.TemporaryDirectory() as tmp:
        cfg = compose(["logger=none", f"scale.max_iterations={WARMUP + ITERATIONS}", *overrides])
        cfg.scale.log_interval = 10**9
        set_torch_threads(int(cfg.torch_threads))
        trainer = Trainer(cfg, RunDir(Path(tmp) / "bench"))
        trainer.env.sim.step = _Timed(trainer.env.sim.step)
        trainer.alg.act = _Timed(trainer.alg.act)
        trainer.train(hook=split)
        with trainer.run.curve.open() as f:
            rows = list(csv.DictReader(f))[WARMUP:]
    collect = np.array([float(r["collect_s"]) for r in rows])
    update = np.array([float(r["update_s"]) for r in rows])
    physics, inference = np.array(physics_s[WARMUP:]), np.array(inference_s[WARMUP:])
    samples = cfg.algo.num_steps_per_env * cfg.task.num_envs
    result = {
        "backend": cfg.sim.backend,
        "terrain": cfg.terrain.name,
        "representation": _representation(cfg),
        "num_envs": int(cfg.task.num_envs),
        "steps_per_env": int(cfg.algo.num_steps_per_env),
        "learning_epochs": int(cfg.algo.num_learning_epochs),
        "actor": cfg.actor.name,
        "encoder": cfg.encoder.name,
        "torch_threads": int(cfg.torch_threads),
        "iterations": len(rows),
        "collect_s": float(np.median(collect)),
        "update_s": float(np.median(update)),
        "physics_s": float(np.median(physics)),
        "inference_s": float(np.median(inference)),
        "task_s": float(np.median(collect - physics - inference)),
        "iteration_s": float(np.median(collect + update)),
        "update_fraction": float(np.median(update / (collect + update))),
        "steps_per_s": float(samples / np.median(collect + update)),
        "collect_steps_per_s": float(samples / np.median(collect)),
    }
    if log:
        log(f"{cfg.terrain.name}: median of {len(rows)} iterations after {WARMUP} warm-up")
    return result


def _representation(cfg) -> str:
    """What the physics collides with: an all-flat grid is the plane (terrain.flat_as_plane)."""
    kinds = {kind for kind, weight in cfg.terrain.mixture.items() if weight > 0}
    return (
        "plane" if kinds == {"flat"} and cfg.terrain.flat_as_plane else cfg.terrain.representation
    )


def table(r: dict) -> str:
    verdict = "meets" if r["update_fraction"] <= 0.25 else "MISSES"
    lines = [_describe(r)]
    if "flat" in r:
        ratio = r["steps_per_s"] / r["flat"]["steps_per_s"]
        lines += ["flat ground (" + " ".join(FLAT) + "):"]
        lines += ["  " + line for line in _describe(r["flat"]).splitlines()]
        lines.append(
            f"target: {r['terrain']} >= {TERRAIN_TARGET}x flat: {ratio:.2f}x "
            f"({'meets' if ratio >= TERRAIN_TARGET else 'MISSES'})"
        )
    lines += ["baseline (" + " ".join(r["baseline_overrides"]) + "):"]
    lines += ["  " + line for line in _describe(r["baseline"]).splitlines()]
    plane = r["plane_physics_env_steps_per_s"]
    lines.append(
        f"raw physics on the plane: {plane:,.0f} env steps/s; training reaches "
        f"{r['steps_per_s'] / plane:.2f}x of it"
        + (f" (flat {r['flat']['steps_per_s'] / plane:.2f}x)" if "flat" in r else "")
    )
    lines.append(
        f"target: update <= 25 % of an iteration: {100 * r['update_fraction']:.1f} % "
        f"({verdict}); baseline {100 * r['baseline']['update_fraction']:.1f} %; "
        f"iteration {r['baseline']['iteration_s'] / r['iteration_s']:.2f}x faster"
    )
    return "\n".join(lines)


def _describe(r: dict) -> str:
    split = " + ".join(
        f"{name} {r[f'{name}_s']:.2f} s ({100 * r[f'{name}_s'] / r['iteration_s']:.0f} %)"
        for name in ("physics", "task", "inference", "update")
    )
    return "\n".join(
        [
            f"terrain={r['terrain']} ({r['representation']}), N={r['num_envs']} x "
            f"{r['steps_per_env']} steps, {r['learning_epochs']} epochs, actor={r['actor']}, "
            f"encoder={r['encoder']}, torch_threads={r['torch_threads']}",
            f"iteration {r['iteration_s']:.2f} s = {split}",
            f"steps/s {r['steps_per_s']:,.0f} (collection alone {r['collect_steps_per_s']:,.0f})",
        ]
    )
