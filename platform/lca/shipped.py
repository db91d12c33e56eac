"""An experiment's shipped policies evaluated and reported, without training:

    python -m lca.experiment experiments/reference.yaml --evaluate-only [overrides]

Each (policy, seed) of the file that ships under `<shipped>/<policy>/` (seed 0; seed k under
`<shipped>/<policy>-seed<k>/`; default `assets/policies/`) is copied into
`<runs_root>/evaluated/<that folder's name>/` (config, provenance, curve, final checkpoint),
given the evaluation and hardware settings the experiment composes for it (the same cells,
seeds and sizes for every policy), evaluated (tables' results, clips), run through the
hardware-style tasks, and the report is built into the file's `report` folder together with
`training.csv`: each policy's environment steps and wall-clock, as its run recorded them.

With `jobs` > 1 (`--jobs`, or the file's `evaluate_jobs`) the policies' parts (each one's
cells, each one's hardware-style tasks) are evaluated that many at once, each in a process of
its own with one torch and one physics thread: on 2 cores two such processes outrun one with
two threads, because each one's Python work (observations, rewards, inference) runs while the
other steps its physics (reports/benchmarks.md).
"""

from __future__ import annotations

import itertools
import json
import multiprocessing
import shutil
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import pandas as pd
from omegaconf import OmegaConf

from lca.config import compose, set_torch_threads
from lca.evaluate.hardware import run_hardware
from lca.evaluate.policy import final_checkpoint, load_run_config
from lca.evaluate.run import evaluate_and_write
from lca.paths import root
from lca.report.build import build_report
from lca.report.reference import copy_run
from lca.store import COMPLETE


def shipped_dir(spec: dict) -> Path:
    return root() / spec.get("shipped", "assets/policies")


def shipped_name(policy: str, seed: int) -> str:
    """The folder a policy's training seed ships in: the policy's own name for seed 0 (the
    reference set's first), `<policy>-seed<k>` for seed k."""
    return policy if int(seed) == 0 else f"{policy}-seed{seed}"


def shipped_runs(spec: dict) -> dict[tuple[str, int], Path]:
    """Every (policy, seed) of `spec` that ships complete under its `shipped` folder, in the
    file's order (policies, then seeds). A folder whose run trained another seed than its
    name says raises, naming both."""
    shipped = shipped_dir(spec)
    found = {}
    for policy, seed in itertools.product(spec["policies"], spec["seeds"]):
        folder = shipped / shipped_name(policy, seed)
        if not (folder / COMPLETE).exists():
            continue
        trained = OmegaConf.load(folder / "config.yaml").seed
        if int(trained) != int(seed):
            raise ValueError(
                f"{folder}: its run trained seed {trained}, its name says seed {seed} "
                f"(seed {trained} ships as {shipped_name(policy, trained)}/)"
            )
        found[(policy, int(seed))] = folder
    return found


def evaluated_copy(
    policy: str, shipped: Path, out: Path, overrides: list[str], threads: int = 0
) -> Path:
    """A fresh run directory `out` holding `shipped`'s policy, with the evaluation and
    hardware settings of `policy=<policy> <overrides>` (and `threads` physics threads). An
    earlier copy's finished rounds stay: the evaluation reuses those its stamp still matches
    (`lca.evaluate.protocol.discard_stale_rounds`), so an interrupted or extended evaluation
    goes on where it was."""
    composed = compose([f"policy={policy}", *overrides])
    evaluation = OmegaConf.merge(composed.eval, {"reference": []})
    sim = {"num_threads": threads} if threads else {}
    rounds, kept = out / "eval", out.parent / f".{out.name}.eval"
    if rounds.is_dir():
        shutil.rmtree(kept, ignore_errors=True)
        rounds.replace(kept)
    checkpoint = final_checkpoint(shipped)
    copy_run(shipped, out, checkpoint, eval=evaluation, hardware=composed.hardware, sim=sim)
    if kept.is_dir():
        kept.replace(rounds)
    return out


def evaluate_part(
    part: str, policy: str, shipped: Path, out: Path, overrides: list[str], threads: int, log=print
) -> int:
    """One part of a shipped policy's evaluation into its own copy `out`: `cells` (the
    tables' results and clips) or `hardware` (the hardware-style tasks). `threads` > 0 pins
    torch and the physics to that many threads. Returns the rounds an earlier call had
    finished and this one kept."""
    t0, started = time.perf_counter(), time.time()
    set_torch_threads(threads)
    run = evaluated_copy(policy, shipped, out, overrides, threads)
    reused = 0
    if part == "cells":
        evaluate_and_write(run, log=log)
        reused = sum(f.stat().st_mtime < started for f in (run / "eval").glob("*/episode_*.csv"))
    else:
        run_hardware(run, load_run_config(run), log=log)
    kept = f" ({reused} rounds kept from an earlier call)" if reused else ""
    log(f"[lca] {policy}: {part} evaluated in {time.perf_counter() - t0:.0f} s{kept}")
    return reused


def join_hardware(source: Path, run: Path) -> None:
    """Move the hardware-style tasks' files from their copy `source` into `run`."""
    (source / "hardware.csv").replace(run / "hardware.csv")
    clips = sorted((source / "clips").glob("hw_*"))
    if clips:
        (run / "clips").mkdir(exist_ok=True)
    for clip in clips:
        clip.replace(run / "clips" / clip.name)
    shutil.rmtree(source)


def training_table(runs: dict[tuple[str, int], Path]) -> pd.DataFrame:
    """One row per (policy, seed): the environment steps and wall-clock of its run (its
    curve's last row), and where it started (a warm start's checkpoint, from its config)."""
    rows = []
    for (policy, seed), run in runs.items():
        last = pd.read_csv(run / "train_curve.csv").iloc[-1]
        cfg = OmegaConf.load(run / "config.yaml")
        start = cfg.algo.get("init_from", "") or ""
        rows.append(
            {
                "policy": policy,
                "seed": seed,
                "label": cfg.policy.label,
                "iterations": int(last["iteration"]) + 1,
                "env_steps": int(last["env_steps"]),
                "wall_s": round(float(last["wall_s"]), 1),
                "started_from": start or "scratch",
                "start_env_steps": _run_steps(root() / Path(start).parents[1]) if start else 0,
            }
        )
    return pd.DataFrame(rows)


def training_rates(runs: dict[tuple[str, int], Path]) -> dict[str, float]:
    """Each policy's training rate, environment steps a second over its whole run (its
    curve's last row), the median over its shipped seeds that have a curve."""
    table = training_table({k: r for k, r in runs.items() if (r / "train_curve.csv").exists()})
    if table.empty:
        return {}
    rates = table["env_steps"] / table["wall_s"]
    return {p: float(r) for p, r in rates.groupby(table["policy"]).median().items()}


def _run_steps(run: Path) -> int:
    """The environment steps a run's curve ends at (0 without a curve)."""
    curve = run / "train_curve.csv"
    return int(pd.read_csv(curve).iloc[-1]["env_steps"]) if curve.exists() else 0


def evaluate_only(
    spec: dict, overrides: list[str], runs_root: Path, log=print, jobs: int | None = None
) -> int:
    """Evaluate every shipped (policy, seed) of `spec`, `jobs` at a time (default: the file's
    `evaluate_jobs`, else 1), then build its report. Returns an exit code."""
    shipped = shipped_dir(spec)
    found = shipped_runs(spec)
    missing = [
        shipped_name(*pair)
        for pair in itertools.product(spec["policies"], spec["seeds"])
        if pair not in found
    ]
    if not found:
        log(
            f"[lca] --evaluate-only: none of {spec['policies']} ships under {shipped}/ "
            "(a complete policy folder holds a COMPLETE marker); train them first"
        )
        return 1
    if missing:
        log(f"[lca] --evaluate-only: not shipped yet, left out: {', '.join(missing)}")
    jobs = min(int(jobs or spec.get("evaluate_jobs", 1)), len(found))
    if jobs < 1:
        raise ValueError(f"--jobs / evaluate_jobs: must be >= 1, got {jobs}")
    t0 = time.perf_counter()
    runs = {pair: runs_root / "evaluated" / shipped_name(*pair) for pair in found}
    hardware = bool(spec.get("hardware", True))
    reused = _evaluate_parts(found, runs, overrides, hardware, jobs, log)
    report = root() / spec.get("report", f"reports/{spec['name']}")
    index = build_report(list(runs.values()), report)
    training_table(runs).to_csv(report / "training.csv", index=False)
    seconds = time.perf_counter() - t0
    summary = {"policies": [r.name for r in runs.values()], "jobs": jobs}
    # rounds an earlier, interrupted or smaller call had finished: a warm figure, not a cold one
    summary |= {"rounds_reused": reused, "seconds": round(seconds, 1)}
    (report / "evaluate_only.json").write_text(json.dumps(summary, indent=1) + "\n")
    log(f"[lca] report: {index} ({len(runs)} trained policies, {seconds / 60:.1f} min)")
    return 0


def _evaluate_parts(found, runs, overrides, hardware: bool, jobs: int, log) -> int:
    """Every (policy, seed)'s cells, then every one's hardware-style tasks, as one queue of parts:
    in this process (`jobs` 1), or for `jobs` processes of one thread each, the longest parts
    first, so that no core idles while one policy's whole evaluation finishes alone. A
    hardware part runs in a copy of its own (a run directory is one process's at a time);
    its files then join the run's. Returns the rounds kept from earlier calls."""
    aside_root = next(iter(runs.values())).parent / ".hardware"
    aside = {key: aside_root / runs[key].name for key in found}
    parts = [("cells", key, runs[key]) for key in found]
    parts += [("hardware", key, aside[key]) for key in found] if hardware else []
    if jobs == 1:
        reused = [
            evaluate_part(part, k[0], found[k], out, overrides, 0, log) for part, k, out in parts
        ]
    else:
        log(f"[lca] --evaluate-only: {len(found)} policies, {jobs} processes of 1 thread each")
        # spawn: a fork of a process that already ran torch's thread pool can deadlock
        context = multiprocessing.get_context("spawn")
        with ProcessPoolExecutor(jobs, mp_context=context) as pool:
            futures = [
                pool.submit(evaluate_part, part, key[0], found[key], out, overrides, 1)
                for part, key, out in parts
            ]
            reused = [future.result() for future in futures]  # a part's failure fails the command
    if hardware:
        for key in found:
            join_hardware(aside[key], runs[key])
        shutil.rmtree(aside_root)
    return sum(reused)
