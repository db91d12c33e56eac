"""Full environment policy steps per second against raw batched physics of the same model.

Each row builds one `LocomotionEnv` (observations, rewards, height grids, resets) and times
its `step` with random actions, then times `sim.step(nstep=decimation)` on the very same
batch: ratio = env / raw, both in policy steps per second (the median over interleaved pairs).
"""

from __future__ import annotations

import resource
from collections.abc import Callable

import numpy as np
import torch

from lca.arrays import like, to_numpy
from lca.bench.sim import sizes
from lca.bench.timing import rate
from lca.config import compose
from lca.sim.scene import build_scene
from lca.task.env import LocomotionEnv

# interleaved (env, raw) pairs; the ratio is the median of the pairs' ratios, so the VM's
# drifts (raw physics alone moves by +-4 % between pairs here) cancel within a pair
REPEATS = 5
MIN_SECONDS = 1.5


def _max_rss_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def _rss_mb() -> float:
    """Current resident memory of this process (Linux)."""
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * resource.getpagesize() / 2**20


def measure(cfg, scene, num_envs: int, threads: int) -> dict:
    cfg.task.num_envs = num_envs
    cfg.sim.num_threads = threads
    torch.manual_seed(0)
    rss_before = _rss_mb()
    env = LocomotionEnv(cfg, scene=scene)
    rss_after = _rss_mb()
    actions = 0.3 * torch.randn(num_envs, env.num_actions)
    targets = to_numpy(env.default_joint_pos) + cfg.task.action_scale * actions.numpy()
    targets = like(targets, env.sim.ctrl)
    calls = [0]

    def env_chunk() -> int:
        env.step(actions)
        return num_envs

    def raw_chunk() -> int:
        # the same targets, and a reset every second as falls would cause in the env
        if calls[0] % 50 == 0:
            env.sim.reset()
        env.sim.ctrl[:] = targets
        env.sim.step(nstep=env.decimation)
        calls[0] += 1
        return num_envs

    env_rates, raw_rates = [], []
    for _ in range(REPEATS):  # interleaved, so drifts in machine load hit both alike
        env_rates.append(rate(env_chunk, MIN_SECONDS))
        raw_rates.append(rate(raw_chunk, MIN_SECONDS))
    env_rate, raw_rate = float(np.median(env_rates)), float(np.median(raw_rates))
    return {
        "num_envs": num_envs,
        "threads": threads,
        "steps_per_s": env_rate,
        "raw_steps_per_s": raw_rate,
        "ratio": float(np.median(np.array(env_rates) / np.array(raw_rates))),
        "memory_mb_per_env": max(rss_after - rss_before, 0.0) / num_envs,
    }


def run(overrides: list[str], log: Callable[[str], None] | None = print) -> dict:
    cfg = compose(overrides)
    scene = build_scene(cfg)
    rows = []
    for num_envs, threads in sizes(cfg):
        row = measure(cfg, scene, num_envs, threads)
        rows.append(row)
        if log:
            log(
                f"{cfg.sim.backend} N={num_envs:5d} threads={threads}: env "
                f"{row['steps_per_s']:,.0f} /s, raw {row['raw_steps_per_s']:,.0f} /s, "
                f"ratio {row['ratio']:.2f}"
            )
    return {
        "backend": cfg.sim.backend,
        "policy_steps": "per second, all envs",
        "max_rss_mb": _max_rss_mb(),
        "batched": rows,
    }


def table(result: dict) -> str:
    lines = [
        f"{'num_envs':>8} {'threads':>7} {'env/s':>10} {'raw/s':>10} {'ratio':>6} {'MB/env':>7}"
    ]
    for r in result["batched"]:
        lines.append(
            f"{r['num_envs']:>8} {r['threads']:>7} {r['steps_per_s']:>10,.0f} "
            f"{r['raw_steps_per_s']:>10,.0f} {r['ratio']:>6.2f} {r['memory_mb_per_env']:>7.3f}"
        )
    lines.append(f"peak RSS {result['max_rss_mb']:,.0f} MB")
    hit = [r for r in result["batched"] if r["num_envs"] == 256 and r["threads"] == 2]
    if hit:
        verdict = "meets" if hit[0]["ratio"] >= 0.8 else "MISSES"
        lines.append(f"target: N=256, 2 threads ratio >= 0.8: {hit[0]['ratio']:.2f} ({verdict})")
    return "\n".join(lines)
