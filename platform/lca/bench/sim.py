"""Physics steps per second: one MuJoCo `mj_step` loop against mjbatch at N envs x threads.

Both use the same compiled model (G1 on the configured terrain, PD holding `home`), and
both reset every `RESET_EVERY` physics steps so fallen robots do not skew the state mix.
"""

from __future__ import annotations

from collections.abc import Callable

import mujoco

from lca.bench.timing import median_rate
from lca.config import compose
from lca.sim.backend import make_sim
from lca.sim.scene import build_scene

NUM_ENVS = (64, 256, 1024)
THREADS = (1, 2)
WARP_GPU_ENVS = (1024, 4096)
WARP_CPU_ENVS = (16, 64)
RESET_EVERY = 200  # physics steps (1 s)
REPEATS = 3
MIN_SECONDS = 1.0


def single_rate(model: mujoco.MjModel, key: int, decimation: int) -> float:
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, key)
    counter = [0]

    def chunk() -> int:
        for _ in range(decimation):
            mujoco.mj_step(model, data)
        counter[0] += decimation
        if counter[0] % RESET_EVERY == 0:
            mujoco.mj_resetDataKeyframe(model, data, key)
        return decimation

    return median_rate(chunk, REPEATS, MIN_SECONDS)


def sizes(cfg) -> list[tuple[int, int]]:
    """(num_envs, threads) rows: mjbatch over CPU threads; warp over worlds (a GPU at the
    paper's 4096, warp's CPU device at a few)."""
    if cfg.sim.backend != "warp":
        return [(n, t) for n in NUM_ENVS for t in THREADS]
    from lca.sim.warp_batch import warp_device

    on_gpu = warp_device(cfg.sim.warp_device).startswith("cuda")
    return [(n, 0) for n in (WARP_GPU_ENVS if on_gpu else WARP_CPU_ENVS)]


def batched_rate(scene, sim_cfg, num_envs: int, threads: int, decimation: int) -> float:
    sim_cfg.num_threads = threads
    sim = make_sim(scene, num_envs, sim_cfg, seed=0)
    sim.reset()
    counter = [0]

    def chunk() -> int:
        sim.step(nstep=decimation)
        counter[0] += decimation
        if counter[0] % RESET_EVERY == 0:
            sim.reset()
        return decimation * num_envs

    return median_rate(chunk, REPEATS, MIN_SECONDS)


def run(overrides: list[str], log: Callable[[str], None] | None = print) -> dict:
    cfg = compose(overrides)
    scene = build_scene(cfg)
    decimation = cfg.sim.decimation
    single = single_rate(scene.model, scene.home_key, decimation)
    if log:
        log(f"single mj_step loop: {single:,.0f} steps/s")
    rows = []
    for num_envs, threads in sizes(cfg):
        steps = batched_rate(scene, cfg.sim, num_envs, threads, decimation)
        rows.append({"num_envs": num_envs, "threads": threads, "steps_per_s": steps})
        if log:
            log(
                f"{cfg.sim.backend} N={num_envs:5d} threads={threads}: {steps:,.0f} steps/s "
                f"({steps / single:.2f}x single)"
            )
    return {"backend": cfg.sim.backend, "single_steps_per_s": single, "batched": rows}


def table(result: dict) -> str:
    single = result["single_steps_per_s"]
    lines = [
        f"{'num_envs':>8} {'threads':>7} {'steps/s':>12} {'x single':>9}",
        f"{'1':>8} {'1':>7} {single:>12,.0f} {1.0:>9.2f}   (mj_step loop)",
    ]
    for row in result["batched"]:
        ratio = row["steps_per_s"] / single
        lines.append(
            f"{row['num_envs']:>8} {row['threads']:>7} {row['steps_per_s']:>12,.0f} {ratio:>9.2f}"
        )
    at256 = [r for r in result["batched"] if r["num_envs"] == 256 and r["threads"] == 2]
    if at256:
        ratio = at256[0]["steps_per_s"] / single
        verdict = "meets" if ratio >= 1.6 else "MISSES"
        lines.append(f"target: N=256, 2 threads >= 1.6x single: {ratio:.2f}x ({verdict})")
    return "\n".join(lines)
