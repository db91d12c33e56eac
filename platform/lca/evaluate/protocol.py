"""The paper's evaluation protocol on one run: U units x E episodes x T steps per cell.

Every (cell, episode round) is seeded from the eval seed alone, so all policies meet the same
spawns, commands and noise (common random numbers: paired comparisons across policies).
Each finished round is written to its own file; an interrupted evaluation resumes at the
first missing round and never counts a round twice.
"""

from __future__ import annotations

import copy
import hashlib
import json
import shutil
import time
import zlib
from pathlib import Path

import numpy as np
import pandas as pd
import torch
from omegaconf import DictConfig, OmegaConf

from lca.arrays import to_numpy
from lca.config import load_option
from lca.evaluate.metrics import episode_metrics
from lca.evaluate.policy import final_checkpoint, load_policy, sees_map
from lca.evaluate.rollout import rollout, start, step_only
from lca.evaluate.terrains import eval_mixture
from lca.store import atomic_write, cpu_model
from lca.task.env import LocomotionEnv
from lca.testhook import exit_point


def cell_name(cell) -> str:
    return f"{cell.terrain}-{cell.difficulty}"


def round_seed(base: int, cell, episode: int) -> int:
    return (base * 1_000_003 + zlib.crc32(cell_name(cell).encode()) + episode) % 2**31


def difficulty_config(name: str) -> DictConfig:
    return load_option("difficulty", name)


def trial_config(
    cfg: DictConfig, num_envs: int, episode_s: float, forward: list[float]
) -> DictConfig:
    """A copy of a run's config for testing it: `num_envs` robots, episodes of `episode_s`,
    forward-only commands in `forward` (m/s), nominal friction and mass, no pushes."""
    c = copy.deepcopy(cfg)
    c.task.num_envs = num_envs
    c.task.episode_length_s = episode_s
    c.task.randomization.enabled = False
    c.terrain.levels = False  # a test is its difficulty on every tile, no curriculum
    # and the units spread evenly
    c.terrain.practice, c.terrain.practice_start, c.terrain.practice_end = {}, 0.0, 0.0
    commands = c.task.commands
    commands.lin_vel_x = list(forward)
    commands.lin_vel_y = [0.0, 0.0]
    commands.ang_vel_z = [0.0, 0.0]
    commands.standing_fraction = 0.0
    commands.resample_time_s = 2 * episode_s
    return c


def cell_config(cfg: DictConfig, cell, episode: int = 0) -> DictConfig:
    """The run's config turned into the evaluation setting of one cell's round `episode`.
    Each round draws its own `eval.grid` of tiles from the round's seed, so a cell meets
    rounds x tiles terrain draws while each model holds only one round's boxes (a box costs
    every unit physics time wherever it is: reports/benchmarks.md)."""
    ev = cfg.eval
    episode_s = ev.steps * cfg.sim.timestep * cfg.sim.decimation
    c = trial_config(cfg, ev.units, episode_s, ev.command_x)
    c.terrain.mixture = eval_mixture(cell.terrain)
    c.terrain.rows, c.terrain.cols = ev.grid
    c.terrain.name = cell.terrain
    c.terrain.seed = round_seed(ev.seed, cell, episode)
    c.difficulty = difficulty_config(cell.difficulty)
    return c


@torch.inference_mode()
def run_round(env: LocomotionEnv, policy, steps: int) -> dict[str, np.ndarray]:
    """One episode for every unit; a unit stops counting at its first termination."""
    n = env.num_envs
    obs = start(env, policy)
    alive = np.ones(n, dtype=bool)
    success = np.zeros(n, dtype=bool)
    alive_steps = np.zeros(n)
    impacts = np.zeros(n)
    track = np.zeros(n)
    command_x = to_numpy(env.commands.value[:, 0]).copy()
    for _, m in rollout(env, policy, obs, steps):
        alive_steps += alive
        impacts += alive & m["lateral_impact"]
        track += np.where(alive, m["track_error"], 0.0)
        success |= alive & m["time_out"]
        alive &= ~(m["terminated"] | m["time_out"])
        if not alive.any():
            break
        step_only(env, alive)
    out = episode_metrics(alive_steps, impacts, track, success)
    out["command_x"] = command_x
    return out


def evaluate_run(run_dir: Path, cfg: DictConfig, log=print) -> pd.DataFrame:
    """Run every missing (cell, episode) round, then return all episodes of the run."""
    run_dir = Path(run_dir)
    ev = cfg.eval
    checkpoint = final_checkpoint(run_dir)
    perception = sees_map(checkpoint)
    out_dir = run_dir / "eval"
    discard_stale_rounds(out_dir, cfg, checkpoint, log)
    written = 0
    for cell in ev.cells:
        name = cell_name(cell)
        todo = [e for e in range(ev.episodes) if not (out_dir / name / f"episode_{e}.csv").exists()]
        if not todo:
            continue
        policy = None
        for episode in todo:
            t0 = time.perf_counter()
            env = LocomotionEnv(cell_config(cfg, cell, episode))
            env.set_perception(perception)
            # the rounds' envs differ in terrain only: one actor serves them all
            if policy is None:
                policy = load_policy(cfg, env, checkpoint)
            env.reseed(round_seed(ev.seed, cell, episode))
            result = run_round(env, policy, ev.steps)
            frame = pd.DataFrame(result)
            frame.insert(0, "unit", np.arange(ev.units))
            frame.insert(1, "episode", episode)
            atomic_write(out_dir / name / f"episode_{episode}.csv", frame.to_csv(index=False))
            written += 1
            exit_point("round", written)
            if log:
                rate = ev.units * ev.steps / (time.perf_counter() - t0)
                log(
                    f"[lca] eval {run_dir.name} {name} episode {episode + 1}/{ev.episodes}: "
                    f"success {frame['success'].mean():.1f} % ({rate:,.0f} steps/s)"
                )
    return collect_episodes(run_dir, cfg)


NOT_PROTOCOL = ("videos", "video_seconds")  # eval keys that do not change the results
# bump when the protocol's code changes its results, so that older rounds are run again
# (2: each round draws its own terrain)
PROTOCOL_VERSION = 2


def discard_stale_rounds(out_dir: Path, cfg: DictConfig, checkpoint: Path, log=print) -> None:
    """Finished rounds are reused only under the same protocol, checkpoint, configured physics
    threads and CPU (the last two change rounding, and over 1000 steps some falls:
    reports/benchmarks.md); otherwise start afresh. The process's torch threads are not
    stamped: `python -m lca.evaluate` leaves them at torch's default."""
    protocol = OmegaConf.to_container(cfg.eval, resolve=True)
    for key in NOT_PROTOCOL:
        protocol.pop(key, None)
    protocol["protocol_version"] = PROTOCOL_VERSION
    protocol["checkpoint_sha256"] = hashlib.sha256(Path(checkpoint).read_bytes()).hexdigest()
    protocol["sim_threads"] = int(cfg.sim.num_threads)
    protocol["cpu"] = cpu_model()
    settings = json.dumps(protocol, sort_keys=True)
    stamp = out_dir / "protocol.json"
    if out_dir.exists() and (not stamp.exists() or stamp.read_text() != settings):
        if log:
            log(f"[lca] eval settings changed: discarding the rounds in {out_dir}")
        shutil.rmtree(out_dir)
    atomic_write(stamp, settings)


def collect_episodes(run_dir: Path, cfg: DictConfig) -> pd.DataFrame:
    frames = []
    for cell in cfg.eval.cells:
        for episode in range(cfg.eval.episodes):
            path = Path(run_dir) / "eval" / cell_name(cell) / f"episode_{episode}.csv"
            frame = pd.read_csv(path)
            frame.insert(0, "cell_terrain", cell.terrain)
            frame.insert(1, "cell_difficulty", cell.difficulty)
            frames.append(frame)
    return pd.concat(frames, ignore_index=True)
