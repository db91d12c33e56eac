"""Run a declarative experiment file as one Hydra multirun, or plan it (`--dry-run`).

    python -m lca.experiment experiments/paper_sim.yaml --dry-run [overrides]
    python -m lca.experiment experiments/paper_sim.yaml [overrides]
    python -m lca.experiment experiments/reference.yaml --evaluate-only [overrides]

The file lists named policies (conf/policy/), seeds, overrides and a launcher; the multirun
writes one run directory per (policy, seed) under runs/<name>/ and the report when it ends;
complete runs are skipped. `--evaluate-only` trains nothing: it evaluates the policies the
file ships (`lca.shipped`) and rebuilds its report.
"""

from __future__ import annotations

import argparse
import itertools
import json
import subprocess
import sys
from pathlib import Path

from omegaconf import OmegaConf

from lca.cli import split_option
from lca.config import compose
from lca.paths import root

REPO = root()
BENCH_DIR = REPO / "reports" / "bench"


def load_experiment(path: Path) -> dict:
    spec = OmegaConf.to_container(OmegaConf.load(path), resolve=True)
    for key in ("name", "policies", "seeds"):
        if key not in spec:
            raise ValueError(f"{path}: missing key '{key}'")
    spec.setdefault("overrides", [])
    spec.setdefault("launcher", "local")
    spec.setdefault("table", "simulation")
    spec.setdefault("runs_root", f"runs/{spec['name']}")
    return spec


def missing_sweeps(spec: dict, done: set[tuple[str, int]]) -> list[dict]:
    """The multiruns that train every (policy, seed) of `spec` not in `done`: a multirun is a
    product of policies and seeds, so the seeds that miss the same policies share one."""
    missing: dict[int, list[str]] = {}
    for seed in spec["seeds"]:
        policies = [p for p in spec["policies"] if (p, int(seed)) not in done]
        if policies:
            missing[seed] = policies
    groups: dict[tuple[str, ...], list[int]] = {}
    for seed, policies in missing.items():
        groups.setdefault(tuple(policies), []).append(seed)
    return [spec | {"policies": list(p), "seeds": seeds} for p, seeds in groups.items()]


def sweep_command(spec: dict, extra: list[str], runs_root: str) -> list[str]:
    return [
        sys.executable,
        str(REPO / "run.py"),
        "-m",
        f"policy={','.join(spec['policies'])}",
        f"seed={','.join(str(s) for s in spec['seeds'])}",
        *spec["overrides"],
        *extra,
        f"hydra/launcher={spec['launcher']}",
        f"runs_root={runs_root}",
    ]


def estimate_seconds(overrides: list[str], train_rate: float | None = None) -> dict:
    """Cost of one run from the measured benchmark throughput (reports/bench/*.json), or
    from `train_rate` (environment steps a second) where the policy's own runs measured it."""
    cfg = compose(overrides)
    train_steps = cfg.scale.max_iterations * cfg.algo.num_steps_per_env * cfg.task.num_envs
    ev = cfg.eval
    eval_steps = len(ev.cells) * ev.units * ev.episodes * ev.steps
    out = {"train_env_steps": int(train_steps), "eval_env_steps": int(eval_steps)}
    out["backend"] = cfg.sim.backend
    suffix = "_warp" if cfg.sim.backend == "warp" else ""  # the chosen backend's own rates
    train, env = BENCH_DIR / f"train{suffix}.json", BENCH_DIR / f"env{suffix}.json"
    if train.exists() and env.exists():
        rows = json.loads(env.read_text())["batched"]
        eval_rate = max(r["steps_per_s"] for r in rows)
        out |= {
            "train_steps_per_s": train_rate or json.loads(train.read_text())["steps_per_s"],
            "eval_steps_per_s": eval_rate,
        }
        out["seconds"] = train_steps / out["train_steps_per_s"] + eval_steps / eval_rate
    return out


def print_plan(
    spec: dict, sweeps: list[dict], extra: list[str], runs_root: str, rates: dict
) -> None:
    """`--dry-run`: every planned run, its environment steps and cost, and the commands.
    `rates`: policy -> training steps/s its shipped runs measured (the benchmark's otherwise:
    the CNN pair trains ~4x slower than the MLP the benchmark measures)."""
    plan = [pair for s in sweeps for pair in itertools.product(s["policies"], s["seeds"])]
    for policy, seed in plan:
        print(f"  policy={policy} seed={seed} {' '.join(spec['overrides'] + extra)}")
    costs = {
        p: estimate_seconds([f"policy={p}", *spec["overrides"], *extra], rates.get(p))
        for p in dict.fromkeys(p for p, _ in plan)
    }
    cost = costs[plan[0][0]]
    print(f"{len(plan)} runs into {runs_root}/ with launcher '{spec['launcher']}'")
    print(
        f"per run: {cost['train_env_steps']:,} training + {cost['eval_env_steps']:,} "
        "evaluation env steps"
    )
    if spec["table"] == "hardware":
        print("then: `python -m lca.hardware` on each run (4 tasks x trials), and the report")
    if "seconds" not in cost:
        print(
            "estimated cost: unknown (run `python -m lca.bench train` and `python -m "
            f"lca.bench env` with sim.backend={cost['backend']} to measure throughput)"
        )
    elif rates.keys() & costs.keys():
        total = sum(costs[p]["seconds"] for p, _ in plan)
        each = ", ".join(
            f"{p} {c['seconds'] / 3600:.2f} h ({c['train_steps_per_s']:,.0f} steps/s, "
            f"{'its shipped runs' if p in rates else '`python -m lca.bench train`'})"
            for p, c in costs.items()
        )
        print(f"estimated cost: {total / 3600:.1f} core-pair hours in all; per run: {each}")
    else:
        total = cost["seconds"] * len(plan)
        print(
            f"estimated cost: {cost['seconds'] / 3600:.2f} h per run, {total / 3600:.1f} "
            f"core-pair hours in all (from {cost['train_steps_per_s']:,.0f} training and "
            f"{cost['eval_steps_per_s']:,.0f} evaluation steps/s measured by "
            f"`python -m lca.bench train|env` with sim.backend={cost['backend']})"
        )
    for s in sweeps:
        print("command:", " ".join(sweep_command(s, extra, runs_root)))


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m lca.experiment")
    parser.add_argument("file", type=Path)
    parser.add_argument("--dry-run", action="store_true", help="print the plan and its cost")
    parser.add_argument(
        "--evaluate-only",
        action="store_true",
        help="evaluate the shipped policies (no training) and rebuild the file's report",
    )
    parser.add_argument(
        "--jobs",
        type=int,
        default=None,
        help="with --evaluate-only: policies evaluated at once (default: the file's "
        "evaluate_jobs, else 1)",
    )
    parser.add_argument("overrides", nargs="*")
    args = parser.parse_intermixed_args(argv)
    spec = load_experiment(args.file)
    roots, extra = split_option(args.overrides, "runs_root")
    runs_root = roots[-1] if roots else spec["runs_root"]
    launchers, extra = split_option(extra, "hydra/launcher")  # the command line's wins
    spec["launcher"] = launchers[-1] if launchers else spec["launcher"]
    if args.evaluate_only:
        from lca.shipped import evaluate_only

        return evaluate_only(spec, spec["overrides"] + extra, Path(REPO, runs_root), jobs=args.jobs)
    sweeps, done = [spec], {}
    if "shipped" in spec:  # a (policy, seed) that ships is not trained again
        from lca.shipped import shipped_name, shipped_runs

        done = shipped_runs(spec)
        if done:
            names = ", ".join(shipped_name(*pair) for pair in done)
            print(f"[lca] shipped already, not trained again: {names}")
        sweeps = missing_sweeps(spec, set(done))
        if not sweeps:
            print("[lca] every policy ships: nothing to train (--evaluate-only reports them)")
            return 0
    if args.dry_run:
        from lca.shipped import training_rates

        print_plan(spec, sweeps, extra, runs_root, training_rates(done))
        return 0
    training = [o for o in extra if not o.startswith("hardware.")]  # not part of a run's identity
    code = 0
    for s in sweeps:
        code = code or subprocess.call(sweep_command(s, training, runs_root), cwd=REPO)
    if code != 0 or spec["table"] != "hardware":
        return code
    return run_hardware_stage(spec, extra, Path(REPO, runs_root))


def run_hardware_stage(spec: dict, extra: list[str], runs_root: Path) -> int:
    """The hardware tasks on every run of this experiment, then the report."""
    from lca.evaluate.hardware import run_hardware
    from lca.evaluate.policy import load_run_config
    from lca.report.build import build_report
    from lca.report.collect import find_run_dirs, run_status

    wanted = {f"policy={p}" for p in spec["policies"]}
    runs = []
    for run_dir in find_run_dirs([runs_root]):
        if run_status(run_dir)[0] != "complete":
            print(f"[lca] hardware: skipping {run_dir} ({run_status(run_dir)[0]})")
            continue
        overrides = json.loads((run_dir / "provenance.json").read_text())["overrides"]
        if wanted & set(overrides):
            hw = [o for o in extra if o.startswith("hardware.")]
            run_hardware(run_dir, load_run_config(run_dir, hw))
            runs.append(run_dir)
    index = build_report(runs, runs_root / "report_hardware")
    print(f"[lca] hardware report: {index}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
