"""Time-to-walk: train a blind MLP from scratch at `scale=cpu` until it walks, on flat ground
or (`terrain=mixed`) on the paper's terrain.

    python -m lca.bench walk [--json] [overrides] [cap_s=10800] [eval_every_s=240]
        [iterations=2450] [until=0] [eval_from=0] [run=runs/bench_walk] [resume=false]
        [stop=true] [confirm_units=256] [variant=<name>] [figure=<png>]

Every `eval_every_s` of training wall-clock the current policy is evaluated in-process with
the paper's protocol on a flat cell (forward commands 0.3-0.6 m/s, 1000-step episodes,
observation noise, no randomisation), and on a zero command (16 units, 5 s); that time is not
counted. The policy *walks* at the first evaluation with success >= 90 %, tracking error
<= 20 cm/s and a base speed <= 20 cm/s when told to stand, while the objective is the paper's
(the reward curriculum, if any, has finished). Trained on terrain, it is also probed on
stairs and uneven terrain at medium difficulty and walks only with >= 80 % success on each.
A probe that walks is evaluated again at once with `confirm_units` units on each cell (a
second row of the same iteration, `confirm` 1), and the run walks only if that one does too.
Reports time_to_walk_s, steps_to_walk, steps/s, writes the curve figure
reports/bench/walk.png (walk_terrain.png and walk_terrain.json on terrain, so the flat result
stays; `variant=terrain_r5`: walk_terrain_r5.*) and the run directory (a complete run:
config, provenance, curve, checkpoints, exported policy).
"""

from __future__ import annotations

import math
import shutil
from collections.abc import Callable
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402
import torch  # noqa: E402
from omegaconf import OmegaConf  # noqa: E402

from lca.cli import split_option  # noqa: E402
from lca.config import compose  # noqa: E402
from lca.config.runtime import set_torch_threads  # noqa: E402
from lca.evaluate.config import EvalCell  # noqa: E402
from lca.evaluate.probe import TrainingProbe  # noqa: E402
from lca.learn.train_cfg import build_train_cfg  # noqa: E402
from lca.learn.trainer import Trainer  # noqa: E402
from lca.paths import reports_dir
from lca.store import RunDir  # noqa: E402

# the blind MLP of the recipe (reports/learning.md): mirror augmentation, which scale=cpu
# leaves off for the CNN's sake, and legs and feet as the only colliding parts on flat ground
BASE = [
    "terrain=flat",
    "curriculum=blind",
    "actor=mlp",
    "encoder=mlp",
    "logger=none",
    "algo.symmetry=true",
    "robot.collision_parts=[feet,legs]",
]
# the probe's protocol, recorded in the run's config.yaml so `python -m lca.evaluate` on the
# run (flat cell) repeats the last probe exactly: same cell config, seeds and sizes
PROTOCOL = ["eval.units=64", "eval.episodes=1", "eval.steps=1000"]
REPORTS = reports_dir()
FLAT_CELL = EvalCell("flat", "medium")
SUCCESS_MIN = 90.0  # %
TRACK_MAX = 20.0  # cm/s
# a forward-only probe passes a policy that walks forward whatever it is told (every walker
# of reports/learning.md did): it must also stand still when the command is zero
STILL_MAX = 20.0  # cm/s of base speed under a zero command
STILL_UNITS, STILL_STEPS = 16, 250
TERRAIN_CELLS = (EvalCell("stairs", "medium"), EvalCell("uneven", "medium"))
TERRAIN_SUCCESS_MIN = 80.0  # % on each terrain cell, for a run trained on terrain
OPTIONS = {
    "cap_s": 3 * 3600.0,
    "eval_every_s": 240.0,
    "iterations": 2450,  # the recipe's schedule (scale=cpu's curricula are fractions of it)
    # no evaluation before this iteration (0: from the start): before the reward curriculum
    # ends none could count as a walk, and each costs ~35 s of a long run
    "eval_from": 0,
    # a probe that walks is evaluated again with this many units on each cell (0: not) and
    # the run walks only if that agrees: a 64-unit probe is +-6 points on stairs (H3 probed
    # 81.2 %, 256 episodes gave 71.9 %: reports/learning.md)
    "confirm_units": 256,
    "until": 0,  # stop after this many iterations (0: none), the schedule still `iterations` long
    "run": "runs/bench_walk",
    "resume": "false",
    "stop": "true",
    # the result's name: walk_<variant>.json and .png (default: walk, walk_terrain on
    # terrain), so that a lever's run does not overwrite the recipe's result
    "variant": "",
    "figure": "",  # default: reports/bench/walk_<variant>.png
}


def parse(args: list[str]) -> tuple[dict, list[str]]:
    opts = dict(OPTIONS)
    for key, default in OPTIONS.items():
        values, args = split_option(args, key)
        if values:
            opts[key] = type(default)(values[-1])
    return opts, args


def walks(row: dict) -> bool:
    on_terrain = [row[k] for k in terrain_keys() if k in row and not math.isnan(row[k])]
    return (
        row["success"] >= SUCCESS_MIN
        and row["track_cm_s"] <= TRACK_MAX
        and row.get("still_cm_s", math.nan) <= STILL_MAX
        and bool(row.get("paper_objective", row["penalty_scale"] >= 1.0))
        and all(success >= TERRAIN_SUCCESS_MIN for success in on_terrain)
    )


def counts(row: dict, confirm_units: int) -> bool:
    """A probe row that makes the run walk: it walks and, when confirmation is asked for,
    it is the larger evaluation."""
    return walks(row) and (confirm_units <= 0 or bool(row.get("confirm", 0) == 1))


def terrain_keys() -> list[str]:
    """The probe columns of the terrain cells: `<terrain>_success`."""
    return [f"{cell.terrain}_success" for cell in TERRAIN_CELLS]


def run(args: list[str], log: Callable[[str], None] | None = print) -> dict:
    opts, overrides = parse(args)
    overrides = [*BASE, *PROTOCOL, f"scale.max_iterations={int(opts['iterations'])}", *overrides]
    cfg = compose(overrides)
    run = RunDir(opts["run"])
    if opts["resume"] != "true":
        shutil.rmtree(run.path, ignore_errors=True)
    elif run.complete:
        rows = TrainingProbe.read(run.path / "probe_evals.csv")
        walked = next((r for r in rows if counts(r, int(opts["confirm_units"]))), None)
        return summarise(run, overrides, opts, walked)
    run.path.mkdir(parents=True, exist_ok=True)
    run.write_provenance(cfg, overrides, {"bench": "walk"})
    set_torch_threads(int(cfg.torch_threads))
    # the probes' networks are built before the trainer's, as always: the trainer seeds torch
    train_cfg = build_train_cfg(cfg, run.path.name)
    out = run.path / "probe_evals.csv"
    probes = Probes(cfg, out, train_cfg, cfg.eval.units)
    trainer = Trainer(cfg, run)
    # the confirmation's probes are built at the first walking probe only
    state = {"next": 0.0, "walked": None, "confirm": None}
    confirm_units = int(opts["confirm_units"])
    for row in TrainingProbe.read(out):  # a resumed benchmark keeps its earlier evaluations
        state["next"] = row["train_wall_s"] + opts["eval_every_s"]
        state["walked"] = state["walked"] or (row if counts(row, confirm_units) else None)

    def hook(trainer: Trainer, it: int, row: dict) -> bool:
        wall = float(row["wall_s"])
        last = it + 1 == trainer.total or wall >= opts["cap_s"]
        last = last or 0 < opts["until"] <= it + 1
        if (wall < state["next"] or it + 1 < opts["eval_from"]) and not last:
            return False
        state["next"] = wall + opts["eval_every_s"]
        entry = {
            "iteration": it,
            "env_steps": row["env_steps"],
            "train_wall_s": wall,
            "penalty_scale": row["penalty_scale"],
            # the table's weights, unclipped: the curriculum is over and no clipping is on
            "paper_objective": int(trainer.rewards.done and not cfg.task.only_positive_rewards),
            "confirm": 0,
        }
        entry |= probes.evaluate(trainer.alg.get_policy())
        probes.record(entry, log)
        trainer.save(f"probe_it{it}.pt", it)  # each evaluated policy, to look at or resume
        if walks(entry) and state["walked"] is None and confirm_units > 0:
            if state["confirm"] is None:  # its networks' init: not from the training's stream
                with torch.random.fork_rng(devices=[]):
                    state["confirm"] = Probes(cfg, out, train_cfg, confirm_units)
            confirm = state["confirm"]
            entry = {**entry, **confirm.evaluate(trainer.alg.get_policy()), "confirm": 1}
            confirm.record(entry, log)
        if counts(entry, confirm_units) and state["walked"] is None:
            state["walked"] = entry
        return last or (state["walked"] is not None and opts["stop"] == "true")

    if not run.complete:
        with run.lock():
            trainer.train(hook=hook)
            trainer.export()
    result = summarise(run, overrides, opts, state["walked"])
    run.mark_complete({k: v for k, v in result.items() if k != "evals"})
    return result


class Probes:
    """The walk's evaluations of one size: forward commands on the flat cell, a zero command
    there (at most STILL_UNITS units) and, trained on terrain, stairs and uneven ground."""

    def __init__(self, cfg, out: Path, train_cfg: dict, units: int):
        steps = cfg.eval.steps
        self.forward = TrainingProbe(cfg, out, FLAT_CELL, units, steps, train_cfg)
        self.still = TrainingProbe(  # evaluates only: its figure goes into the forward row
            cfg,
            None,
            FLAT_CELL,
            min(STILL_UNITS, units),
            min(STILL_STEPS, steps),
            train_cfg,
            command_x=[0.0, 0.0],
        )
        self.terrain = {
            f"{cell.terrain}_success": TrainingProbe(cfg, None, cell, units, steps, train_cfg)
            for cell in (TERRAIN_CELLS if cfg.terrain.name != "flat" else ())
        }

    def evaluate(self, actor) -> dict:
        result = self.forward.evaluate(actor)
        standing = self.still.evaluate(actor)
        result["still_cm_s"] = standing["track_cm_s"]
        result["eval_s"] += standing["eval_s"]
        for key, probe in self.terrain.items():
            on_terrain = probe.evaluate(actor)
            result[key] = on_terrain["success"]
            result["eval_s"] += on_terrain["eval_s"]
        return result

    def record(self, entry: dict, log: Callable[[str], None] | None) -> None:
        self.forward.record(entry)
        if log:
            what = f"confirm x{entry['units']} | " if entry.get("confirm") else ""
            log(
                f"[walk] {entry['train_wall_s'] / 60:6.1f} min "
                f"{entry['env_steps'] / 1e6:6.2f} M steps | {what}success "
                f"{entry['success']:5.1f} % | track {entry['track_cm_s']:5.1f} cm/s | "
                f"still {entry['still_cm_s']:5.1f} cm/s | "
                + "".join(f"{k.split('_')[0]} {entry[k]:5.1f} % | " for k in self.terrain)
                + f"penalties x{entry['penalty_scale']:.2f} | eval {entry['eval_s']:.0f} s"
            )


def summarise(run: RunDir, overrides: list[str], opts: dict, walked: dict | None) -> dict:
    # the run's own config, not a new composition: conf/ may have changed while it trained
    cfg = OmegaConf.load(run.path / "config.yaml")
    curve = pd.read_csv(run.curve)
    evals = pd.read_csv(run.path / "probe_evals.csv")
    on_terrain = cfg.terrain.name != "flat"
    variant = opts["variant"] or ("terrain" if on_terrain else "")
    default = REPORTS / "bench" / (f"walk_{variant}.png" if variant else "walk.png")
    plot(
        evals,
        Path(opts["figure"] or default),
        f"the {cfg.terrain.name} terrain" if on_terrain else "flat ground",
    )
    train_s = float(curve["wall_s"].iloc[-1])
    return {
        "variant": variant,  # the result's file: walk.json, walk_<variant>.json
        "overrides": overrides,
        "walked": walked is not None,
        "time_to_walk_s": walked["train_wall_s"] if walked else None,
        "steps_to_walk": int(walked["env_steps"]) if walked else None,
        "iterations_to_walk": int(walked["iteration"]) + 1 if walked else None,
        "train_s": train_s,
        "env_steps": int(curve["env_steps"].iloc[-1]),
        "steps_per_s": float(curve["env_steps"].iloc[-1] / train_s),
        "criteria": {
            "success_min": SUCCESS_MIN,
            "track_max_cm_s": TRACK_MAX,
            "still_max_cm_s": STILL_MAX,
            "terrain_success_min": TERRAIN_SUCCESS_MIN,
        },
        "probe": {
            "units": int(cfg.eval.units),
            "steps": int(cfg.eval.steps),
            "cell": "flat-medium",
            "confirm_units": int(opts["confirm_units"]),
            "terrain_cells": [f"{c.terrain}-{c.difficulty}" for c in TERRAIN_CELLS]
            if on_terrain
            else [],
        },
        "evals": evals.to_dict(orient="records"),
        "run_dir": str(run.path),
    }


def plot(evals: pd.DataFrame, out: Path, ground: str = "flat ground") -> None:
    out.parent.mkdir(parents=True, exist_ok=True)
    confirmed = evals[evals["confirm"] == 1] if "confirm" in evals else evals.iloc[:0]
    evals = evals.drop(confirmed.index).reset_index(drop=True)
    fig, axes = plt.subplots(1, 2, figsize=(11, 3.6))
    minutes = evals["train_wall_s"] / 60
    for ax, col, limit, label in (
        (axes[0], "success", SUCCESS_MIN, "success (%)"),
        (axes[1], "track_cm_s", TRACK_MAX, "tracking error (cm/s)"),
    ):
        ax.plot(minutes, evals[col], marker="o", lw=1.5, label="forward 0.3-0.6 m/s")
        if col == "track_cm_s" and "still_cm_s" in evals:
            ax.plot(minutes, evals["still_cm_s"], marker="s", lw=1, label="zero command")
            ax.legend(fontsize=8)
        ax.axhline(limit, color="grey", ls="--", lw=1)
        _mark_objective(ax, evals, minutes)
        ax.set_xlabel("training wall-clock (min, 2 CPU cores)")
        ax.set_title(label, fontsize=10)
        ax.grid(alpha=0.3)
        top = ax.secondary_xaxis(
            "top",
            functions=(
                lambda m, e=evals: _interp(m, e.train_wall_s / 60, e.env_steps / 1e6),
                lambda s, e=evals: _interp(s, e.env_steps / 1e6, e.train_wall_s / 60),
            ),
        )
        # steps per minute vary along a run: ticks even in minutes, labelled in steps
        even = np.linspace(0, float(minutes.max()), 6)
        top.set_xticks(np.round(_interp(even, minutes, evals.env_steps / 1e6), 1))
        top.set_xlabel("environment steps (M)", fontsize=8)
    _plot_terrain_probes(axes[0], evals, minutes)
    _plot_confirmations(axes, confirmed)
    fig.suptitle(
        f"Time to walk on {ground}: blind MLP, the walk recipe "
        "(shaded: under the paper's objective)",
        fontsize=11,
    )
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    plt.close(fig)


def _plot_terrain_probes(ax, evals: pd.DataFrame, minutes: pd.Series) -> None:
    """A run on terrain: its stairs and uneven probes beside flat's success."""
    probed = [
        (cell, key, marker)
        for cell, key, marker in zip(TERRAIN_CELLS, terrain_keys(), "^v", strict=True)
        if key in evals and evals[key].notna().any()
    ]
    for cell, key, marker in probed:
        label = f"{cell.terrain}-{cell.difficulty}"
        ax.plot(minutes, evals[key], marker=marker, lw=1, label=label)
    if probed:
        ax.axhline(TERRAIN_SUCCESS_MIN, color="grey", ls=":", lw=1)
        ax.legend(fontsize=8)


def _plot_confirmations(axes, confirmed: pd.DataFrame) -> None:
    """The larger evaluations of walking probes, as stars at their probes' minutes."""
    if confirmed.empty:
        return
    minutes = confirmed["train_wall_s"] / 60
    units = int(confirmed["units"].iloc[0])
    keys = ["success"] + [k for k in terrain_keys() if k in confirmed]
    for key in keys:
        axes[0].scatter(minutes, confirmed[key], marker="*", s=90, color="black", zorder=5)
    axes[1].scatter(minutes, confirmed["track_cm_s"], marker="*", s=90, color="black", zorder=5)
    axes[0].scatter([], [], marker="*", color="black", label=f"confirmation ({units} units)")
    axes[0].legend(fontsize=8)


def _mark_objective(ax, evals: pd.DataFrame, minutes: pd.Series) -> None:
    """Shade the evaluations made under the paper's objective (the only ones that count) and
    name the stages when the curve joins several runs (a `stage` column)."""
    if "paper_objective" in evals:
        paper = evals["paper_objective"].astype(bool).to_numpy()
        block = (paper != np.roll(paper, 1)).cumsum()  # runs of equal values
        for b in np.unique(block[paper]):
            span = minutes[block == b]
            ax.axvspan(span.min() - 1, span.max() + 1, color="tab:green", alpha=0.1, lw=0)
    if "stage" in evals:
        starts = evals.groupby("stage", sort=False).head(1).index
        for i in starts[1:]:
            ax.axvline(minutes[i], color="tab:purple", ls=":", lw=1)
        for i in starts:
            ax.annotate(
                evals["stage"][i],
                (minutes[i], 1.0),
                xycoords=("data", "axes fraction"),
                xytext=(2, -10),
                textcoords="offset points",
                fontsize=7,
                color="tab:purple",
            )


def _interp(x, xp, fp):
    return np.interp(x, np.asarray(xp, float), np.asarray(fp, float))


def table(r: dict) -> str:
    lines = [
        f"walked: {r['walked']}  time_to_walk_s: {r['time_to_walk_s']}  "
        f"steps_to_walk: {r['steps_to_walk']}  steps/s: {r['steps_per_s']:,.0f}",
        f"{'min':>6} {'M steps':>8} {'success %':>9} {'track cm/s':>10} {'still cm/s':>10} "
        f"{'penalties':>9}",
    ]
    for e in r["evals"]:
        lines.append(
            f"{e['train_wall_s'] / 60:6.1f} {e['env_steps'] / 1e6:8.2f} {e['success']:9.1f} "
            f"{e['track_cm_s']:10.1f} {e.get('still_cm_s', math.nan):10.1f} "
            f"{e['penalty_scale']:9.2f}"
        )
    return "\n".join(lines)
