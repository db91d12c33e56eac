"""How long the run-level statistics take at the paper's table size: 7 policies x 3 training
seeds x 4 cells x 128 units (synthetic episodes), against the unit-level table of the same
episodes (the baseline: what the report computed before seeds were an axis)."""

from __future__ import annotations

import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pandas as pd

from lca.report.seed_figures import profile_figure, seed_figures
from lca.report.seeds import improvement_table, seed_table
from lca.report.tables import long_table

POLICIES = {  # label -> (curriculum, actor, encoder)
    "Blind": ("blind", "mlp", "mlp"),
    "One-Stage MLP": ("one", "mlp", "mlp"),
    "Two-Stage MLP": ("two", "mlp", "mlp"),
    "One-Stage LSTM": ("one", "lstm", "mlp"),
    "Two-Stage LSTM": ("two", "lstm", "mlp"),
    "One-Stage CNN": ("one", "mlp", "cnn"),
    "Two-Stage CNN": ("two", "mlp", "cnn"),
}
CELLS = [(t, d) for t in ("stairs", "uneven") for d in ("medium", "hard")]


class _Run:
    def __init__(self, label, kind, seed, episodes):
        self.label, self.seed, self.episodes = label, seed, episodes
        self.curriculum, self.actor, self.encoder = kind


def synthetic(seeds: int, units: int, episodes: int, rng: np.random.Generator) -> list[_Run]:
    runs = []
    for label, kind in POLICIES.items():
        for seed in range(seeds):
            rows = {
                "unit": np.tile(np.repeat(np.arange(units), episodes), len(CELLS)).astype(str),
                "cell_terrain": np.repeat([t for t, _ in CELLS], units * episodes),
                "cell_difficulty": np.repeat([d for _, d in CELLS], units * episodes),
            }
            n = len(rows["unit"])
            rows["success"] = 100.0 * (rng.uniform(size=n) < rng.uniform(0.6, 1.0))
            rows["contacts_per_step"] = rng.gamma(2.0, 1.0, n)
            rows["track_cm_s"] = rng.normal(15, 2, n)
            frame = pd.DataFrame(rows)
            frame["unit"] = f"{seed}:" + frame["unit"]
            runs.append(_Run(label, kind, seed, frame.assign(policy=label, seed=seed)))
    return runs


def run(overrides: list[str], log: Callable[[str], None] | None = print) -> dict:
    sizes = {"seeds": 3, "units": 128, "episodes": 3}
    for item in overrides:
        key, _, value = item.partition("=")
        sizes[key] = int(value)
    runs = synthetic(sizes["seeds"], sizes["units"], sizes["episodes"], np.random.default_rng(0))
    episodes = pd.concat([r.episodes for r in runs], ignore_index=True)
    timings = {}
    t0 = time.perf_counter()
    long_table(episodes)
    timings["unit_table_s"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    seeds = seed_table(episodes)
    timings["seed_table_s"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    improvement_table(runs)
    timings["improvement_s"] = time.perf_counter() - t0
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        seed_figures(seeds, Path(tmp))
        profile_figure(episodes, Path(tmp) / "profiles.png")
        timings["figures_s"] = time.perf_counter() - t0
    result = {**sizes, "policies": len(POLICIES), "cells": len(CELLS), **timings}
    result["seed_statistics_s"] = timings["seed_table_s"] + timings["improvement_s"]
    return result


def table(r: dict) -> str:
    return "\n".join(
        [
            f"{r['policies']} policies x {r['seeds']} seeds x {r['cells']} cells x {r['units']} "
            f"units x {r['episodes']} episodes",
            f"unit-level table (baseline): {r['unit_table_s']:.2f} s",
            f"seed table {r['seed_table_s']:.2f} s + improvement {r['improvement_s']:.2f} s = "
            f"{r['seed_statistics_s']:.2f} s ({r['seed_statistics_s'] / r['unit_table_s']:.2f}x "
            f"the baseline); figures {r['figures_s']:.2f} s",
        ]
    )
