"""An experiment's shipped policies evaluated and reported, without training:

    python -m lca.experiment experiments/reference.yaml --evaluate-only [overrides]

Each policy of the file that ships under `<shipped>/<policy>/` (default `assets/policies/`) is
copied into `<runs_root>/evaluated/<policy>/` (config, provenance, curve, final checkpoint),
given the evaluation and hardware settings the experiment composes for it (the same cells,
seeds and sizes for every policy), evaluated (tables' results, clips), run through the
hardware-style tasks, and the report is built into the file's `report` folder together with
`training.csv`: each policy's environment steps and wall-clock, as its run recorded them.
"""

from __future__ import annotations

import json
import time
from pathlib import Path

import pandas as pd
from omegaconf import OmegaConf

from lca.config import compose
from lca.evaluate.hardware import run_hardware
from lca.evaluate.policy import final_checkpoint, load_run_config
from lca.evaluate.run import evaluate_and_write
from lca.paths import root
from lca.report.build import build_report
from lca.report.reference import copy_run
from lca.store import COMPLETE


def shipped_dir(spec: dict) -> Path:
    return root() / spec.get("shipped", "assets/policies")


def shipped_policies(spec: dict) -> list[str]:
    """The policies of `spec` that ship complete under its `shipped` folder."""
    shipped = shipped_dir(spec)
    return [p for p in spec["policies"] if (shipped / p / COMPLETE).exists()]


def evaluated_copy(policy: str, shipped: Path, out: Path, overrides: list[str]) -> Path:
    """A fresh run directory `out` holding `shipped`'s policy, with the evaluation and
    hardware settings of `policy=<policy> <overrides>`."""
    composed = compose([f"policy={policy}", *overrides])
    evaluation = OmegaConf.merge(composed.eval, {"reference": []})
    copy_run(shipped, out, final_checkpoint(shipped), eval=evaluation, hardware=composed.hardware)
    return out


def training_table(runs: dict[str, Path]) -> pd.DataFrame:
    """One row per policy: the environment steps and wall-clock of its run (its curve's last
    row), and where it started (a warm start's checkpoint, from its config)."""
    rows = []
    for policy, run in runs.items():
        last = pd.read_csv(run / "train_curve.csv").iloc[-1]
        cfg = OmegaConf.load(run / "config.yaml")
        start = cfg.algo.get("init_from", "") or ""
        rows.append(
            {
                "policy": policy,
                "label": cfg.policy.label,
                "iterations": int(last["iteration"]) + 1,
                "env_steps": int(last["env_steps"]),
                "wall_s": round(float(last["wall_s"]), 1),
                "started_from": start or "scratch",
                "start_env_steps": _run_steps(root() / Path(start).parents[1]) if start else 0,
            }
        )
    return pd.DataFrame(rows)


def _run_steps(run: Path) -> int:
    """The environment steps a run's curve ends at (0 without a curve)."""
    curve = run / "train_curve.csv"
    return int(pd.read_csv(curve).iloc[-1]["env_steps"]) if curve.exists() else 0


def evaluate_only(spec: dict, overrides: list[str], runs_root: Path, log=print) -> int:
    """Evaluate every shipped policy of `spec`, then build its report. Returns an exit code."""
    shipped = shipped_dir(spec)
    found = {p: shipped / p for p in shipped_policies(spec)}
    missing = [p for p in spec["policies"] if p not in found]
    if not found:
        log(
            f"[lca] --evaluate-only: none of {spec['policies']} ships under {shipped}/ "
            "(a complete policy folder holds a COMPLETE marker); train them first"
        )
        return 1
    if missing:
        log(f"[lca] --evaluate-only: not shipped yet, left out: {', '.join(missing)}")
    t0 = time.perf_counter()
    runs = {}
    for policy, folder in found.items():
        run = evaluated_copy(policy, folder, runs_root / "evaluated" / policy, overrides)
        t1 = time.perf_counter()
        evaluate_and_write(run, log=log)
        if spec.get("hardware", True):
            run_hardware(run, load_run_config(run), log=log)
        log(f"[lca] {policy}: evaluated in {time.perf_counter() - t1:.0f} s")
        runs[policy] = run
    report = root() / spec.get("report", f"reports/{spec['name']}")
    index = build_report(list(runs.values()), report)
    training_table(runs).to_csv(report / "training.csv", index=False)
    seconds = time.perf_counter() - t0
    (report / "evaluate_only.json").write_text(
        json.dumps({"policies": list(runs), "seconds": round(seconds, 1)}, indent=1) + "\n"
    )
    log(f"[lca] report: {index} ({len(runs)} policies, {seconds / 60:.1f} min)")
    return 0
