"""Where the reference evaluation's time goes, and the least it can take on this machine:

    python -m lca.bench floor [shipped=blind,one_mlp,two_mlp,one_cnn,two_cnn] [steps=200]

Each shipped policy runs round 0 of every cell of experiments/reference.yaml (its units and
terrain grid, `steps` policy steps), on one thread, with the physics step and the actor timed
apart from the rest of `env.step`. The per-step costs are then scaled to the full evaluation
each policy's shipped `results.parquet` records: the physics by the unit-steps it stepped (a
unit stops stepping at its first fall), the actor and the rest by the rounds' lengths (they
run for every unit until the round ends). Over `processes` processes that share nothing, the
physics alone is the least the cells can take (the floor), and all three parts the least the
whole evaluation can take; the hardware-style tasks and the clips come on top of both.
"""

from __future__ import annotations

import time
from collections.abc import Callable

import pandas as pd
import torch
from omegaconf import OmegaConf

from lca.bench.timing import split_params
from lca.config import compose, set_torch_threads
from lca.evaluate.policy import final_checkpoint, load_policy, load_run_config, sees_map
from lca.evaluate.protocol import cell_config, cell_name, round_seed, run_round
from lca.paths import assets_dir, root
from lca.task.env import LocomotionEnv

DEFAULTS = {"shipped": "", "steps": "200", "processes": "2"}
PARTS = ("physics", "actor", "rest")


class Stopwatch:
    """Seconds spent in the wrapped calls; with `count`, the units each call worked on."""

    def __init__(self, call: Callable, count: Callable | None = None):
        self.call, self.count, self.seconds, self.units = call, count, 0.0, 0

    def __call__(self, *args, **kwargs):
        t0 = time.perf_counter()
        out = self.call(*args, **kwargs)
        self.seconds += time.perf_counter() - t0
        self.units += self.count(*args, **kwargs) if self.count else 0
        return out


def time_round(cfg, cell, checkpoint, steps: int) -> dict:
    """Round 0 of `cell` for `steps` policy steps: seconds per stepped unit-step of the
    physics, and seconds per round step of the actor and of the rest."""
    ev = cfg.eval
    c = cell_config(cfg, cell, 0)
    env = LocomotionEnv(c)
    env.set_perception(sees_map(checkpoint))
    policy = load_policy(cfg, env, checkpoint)
    env.reseed(round_seed(ev.seed, cell, 0))

    def stepped(nstep: int = 1, ids=None) -> float:  # `decimation` calls a policy step
        return (env.num_envs if ids is None else len(ids)) / c.sim.decimation

    physics = env.sim.step = Stopwatch(env.sim.step, stepped)
    actor = Stopwatch(policy, lambda obs: 1)  # units: the round's steps
    actor.reset = policy.reset
    t0 = time.perf_counter()
    run_round(env, actor, steps)
    total = time.perf_counter() - t0
    round_steps = actor.units
    return {
        "physics_per_unit_step": physics.seconds / physics.units,
        "actor_per_step": actor.seconds / round_steps,
        "rest_per_step": (total - physics.seconds - actor.seconds) / round_steps,
        "round_s": total,
        "physics_share": physics.seconds / total,
    }


def full_size(results: pd.DataFrame, terrain: str, difficulty: str) -> tuple[int, int]:
    """(unit-steps stepped, round steps run) of a cell in a shipped evaluation: a round
    runs until its last unit falls or the episode ends."""
    cell = results[(results.cell_terrain == terrain) & (results.cell_difficulty == difficulty)]
    return int(cell.steps.sum()), int(cell.groupby("episode").steps.max().sum())


def run(overrides: list[str], log: Callable[[str], None] | None = print) -> dict:
    params, extra = split_params(overrides, DEFAULTS)
    reference = OmegaConf.to_container(OmegaConf.load(root() / "experiments" / "reference.yaml"))
    policies = params["shipped"].split(",") if params["shipped"] else reference["policies"]
    steps, processes = int(params["steps"]), int(params["processes"])
    set_torch_threads(1)
    rows = []
    for policy in policies:
        shipped = assets_dir() / "policies" / policy
        composed = compose([*reference["overrides"], *extra])  # the evaluation's settings
        cfg = load_run_config(shipped)
        cfg.eval = OmegaConf.merge(composed.eval, {"reference": []})
        cfg.sim.num_threads = 1
        results = pd.read_parquet(shipped / "results.parquet")
        for cell in cfg.eval.cells:
            cost = time_round(cfg, cell, final_checkpoint(shipped), steps)
            unit_steps, round_steps = full_size(results, cell.terrain, cell.difficulty)
            row = {"policy": policy, "cell": cell_name(cell), **cost}
            row["physics_s"] = cost["physics_per_unit_step"] * unit_steps
            row["actor_s"] = cost["actor_per_step"] * round_steps
            row["rest_s"] = cost["rest_per_step"] * round_steps
            rows.append(row)
            if log:
                log(
                    f"[bench] {policy} {row['cell']}: round of {steps} steps "
                    f"{cost['round_s']:.1f} s (physics {cost['physics_share']:.0%}); "
                    f"full size: physics "
                    f"{row['physics_s']:.0f} s, actor {row['actor_s']:.0f} s, rest "
                    f"{row['rest_s']:.0f} s"
                )
    frame = pd.DataFrame(rows)
    totals = {part: float(frame[f"{part}_s"].sum()) for part in PARTS}
    floor_s = totals["physics"] / processes
    cells_s = sum(totals.values()) / processes
    return {
        "policies": policies,
        "steps": steps,
        "processes": processes,
        "overrides": extra,
        "cells": frame.to_dict(orient="records"),
        "totals_s": totals,
        "floor_min": floor_s / 60,
        "cells_min": cells_s / 60,
        "floor_share": floor_s / cells_s,
        "torch": torch.__version__,
    }


def table(result: dict) -> str:
    per_policy = pd.DataFrame(result["cells"]).groupby("policy", sort=False)
    lines = [
        f"reference evaluation's cells, scaled to the shipped evaluations' steps, "
        f"{result['processes']} processes:",
        f"{'policy':<10} {'physics s':>10} {'actor s':>8} {'rest s':>8}",
    ]
    for policy, rows in per_policy:
        lines.append(
            f"{policy:<10} {rows.physics_s.sum():10.0f} {rows.actor_s.sum():8.0f} "
            f"{rows.rest_s.sum():8.0f}"
        )
    lines += [
        f"physics alone (the floor): {result['floor_min']:.1f} min",
        f"physics + actor + rest:    {result['cells_min']:.1f} min "
        f"(the floor is {result['floor_share']:.0%} of it)",
    ]
    return "\n".join(lines)
