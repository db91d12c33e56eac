"""The learning levers, each measured against the same budget.

    python -m lca.bench levers [budget_s=1200 | budget_its=326] [only=a,b] [runs=runs/levers]

Every lever is one run of the time-to-walk benchmark (blind MLP, flat ground, `scale=cpu`)
with the recipe's defaults changed by the lever's overrides, trained for `budget_s` seconds
of wall-clock (probed every quarter of it) or for `budget_its` iterations (the same env
steps for every lever: each collects 6144 a iteration; probed at the end only, and fair
whatever else the machine runs), and evaluated in-process with the paper's protocol on a
flat cell. A finished lever is reused (its run directory holds its result); writes
reports/learning_levers.md.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from lca.bench import env as env_bench
from lca.bench import walk
from lca.cli import split_option
from lca.config import compose
from lca.sim.scene import build_scene

# name -> (what it changes, overrides on top of the scale=cpu recipe)
LEVERS: dict[str, tuple[str, list[str]]] = {
    "recipe": ("the scale=cpu defaults", []),
    "before": (
        "the defaults before the recipe: one action scale 0.25, always only_positive, "
        "no reward or command curriculum",
        [
            "task.action_scale_by_effort=false",
            "task.only_positive_rewards=true",
            "task.reward_curriculum.enabled=false",
            "task.command_curriculum.enabled=false",
        ],
    ),
    "no_curriculum": ("paper penalties from the start", ["task.reward_curriculum.enabled=false"]),
    "no_clipping_stage": (
        "no clipping of the step sum while the curriculum runs",
        ["task.reward_curriculum.only_positive=false"],
    ),
    "isaaclab_gains": (
        "IsaacLab's G1 gains and one action scale 0.5",
        ["robot=g1_isaaclab", "task.action_scale_by_effort=false", "task.action_scale=0.5"],
    ),
    "one_action_scale": ("one action scale 0.25", ["task.action_scale_by_effort=false"]),
    "all_commands": (
        "the paper's command ranges from the start (no forward-only phase)",
        ["task.command_curriculum.enabled=false"],
    ),
    "posture_clipped": (
        "posture terms inside the clip, like every other penalty",
        ["task.reward_curriculum.unclipped=[]"],
    ),
    "no_late_boost": (
        "no late tracking boost (factor 1)",
        ["task.reward_curriculum.boost.track_lin_vel_xy_exp=1.0"],
    ),
    "init_noise_0.5": ("initial action std 0.5", ["actor.init_noise_std=0.5"]),
    "no_symmetry": ("no mirror augmentation", ["algo.symmetry=false"]),
    "fixed_lr": ("fixed learning rate 3e-4", ["algo.schedule=fixed", "algo.learning_rate=3e-4"]),
    "envs_512x12": (
        "512 envs x 12 steps",
        ["task.num_envs=512", "algo.num_steps_per_env=12"],
    ),
    "envs_128x48": (
        "128 envs x 48 steps",
        ["task.num_envs=128", "algo.num_steps_per_env=48"],
    ),
    "small_networks": (
        "actor and critic {256, 128, 128} (report only)",
        ["actor.hidden_dims=[256,128,128]"],
    ),
}


def run(args: list[str], log: Callable[[str], None] | None = print) -> dict:
    budgets, args = split_option(args, "budget_s")
    onlys, args = split_option(args, "only")
    roots, args = split_option(args, "runs")
    its, args = split_option(args, "budget_its")
    budget = float(budgets[-1]) if budgets else 1200.0
    iterations = int(its[-1]) if its else 0
    if iterations:  # the schedule stays the recipe's; the run stops after `iterations`
        budget, args = 1e9, [*args, f"until={iterations}"]
    root = Path(roots[-1] if roots else "runs/levers")
    names = onlys[-1].split(",") if onlys else list(LEVERS)
    unknown = [n for n in names if n not in LEVERS]
    if unknown:
        raise SystemExit(f"only: unknown lever(s) {unknown}; allowed: {list(LEVERS)}")
    results = {}
    for name in names:
        what, overrides = LEVERS[name]
        if log:
            log(f"[levers] {name}: {what}")
        r = walk.run(
            [
                *args,
                *overrides,
                f"cap_s={budget}",
                f"eval_every_s={budget / 4}",
                "stop=false",
                "resume=true",
                f"run={root / name}",
                f"figure={root / name / 'walk.png'}",
            ],
            log=log,
        )
        final = r["evals"][-1]
        results[name] = {
            "what": what,
            "overrides": overrides,
            "success": final["success"],
            "track_cm_s": final["track_cm_s"],
            "mean_steps": final["mean_steps"],
            "still_cm_s": final.get("still_cm_s", float("nan")),
            "env_steps": r["env_steps"],
            "steps_per_s": r["steps_per_s"],
            "time_to_walk_s": r["time_to_walk_s"],
        }
    physics = physics_cost(log)
    label = f"{iterations}-iteration" if iterations else f"{budget / 60:.0f}-minute"
    write_markdown(results, physics, label, walk.REPORTS / "learning_levers.md")
    return {"budget": label, "levers": results, "physics": physics}


# physics-cost levers: env steps/s (N=256, 2 threads, random actions) on flat ground
PHYSICS = {
    "plane (default)": [],
    "heightfield floor": ["terrain.flat_as_plane=false"],
}


def physics_cost(log: Callable[[str], None] | None = print) -> dict:
    rows = {}
    for name, overrides in PHYSICS.items():
        cfg = compose([*walk.BASE, *overrides])
        row = env_bench.measure(cfg, build_scene(cfg), 256, 2)
        rows[name] = {"overrides": overrides, "steps_per_s": row["steps_per_s"]}
        if log:
            log(f"[levers] physics {name}: {row['steps_per_s']:,.0f} env steps/s")
    return rows


def _walked_at(seconds: float | None) -> str:
    return "-" if seconds is None else f"{seconds / 60:.0f} min"


def write_markdown(results: dict, physics: dict, budget: str, path: Path) -> None:
    base = next(iter(physics.values()))["steps_per_s"]
    physics_rows = "\n".join(
        f"| {name} | `{' '.join(r['overrides']) or '-'}` | {r['steps_per_s']:,.0f} | "
        f"{r['steps_per_s'] / base:.2f} |"
        for name, r in physics.items()
    )
    rows = "\n".join(
        f"| {name} | {r['what']} | {r['success']:.1f} | {r['track_cm_s']:.1f} | "
        f"{r.get('still_cm_s', float('nan')):.1f} | {r['env_steps'] / 1e6:.2f} | "
        f"{r['steps_per_s']:,.0f} | "
        f"{_walked_at(r['time_to_walk_s'])} |"
        for name, r in results.items()
    )
    path.write_text(
        f"# Learning levers at a {budget} budget\n\n"
        "`python -m lca.bench levers`: blind MLP, flat ground, `scale=cpu`, 2 CPU cores. "
        "Success and tracking: the paper's protocol on a flat cell (64 units x 1000 steps, "
        "forward 0.3-0.6 m/s) at the end of the budget.\n\n"
        "| lever | change | success (%) | track (cm/s) | still (cm/s) | env steps (M) | "
        "steps/s | walked at |\n"
        "|---|---|---:|---:|---:|---:|---:|---:|\n"
        f"{rows}\n\n"
        "Physics cost on flat ground (`LocomotionEnv.step`, 256 envs, 2 threads, random "
        "actions, median of 3):\n\n"
        "| floor | overrides | env steps/s | ratio |\n|---|---|---:|---:|\n"
        f"{physics_rows}\n"
    )


def table(r: dict) -> str:
    lines = [f"budget: {r['budget']}"]
    for name, x in r["levers"].items():
        lines.append(
            f"{name:>20}: success {x['success']:5.1f} %  track {x['track_cm_s']:5.1f} cm/s  "
            f"{x['env_steps'] / 1e6:5.2f} M steps  {x['steps_per_s']:6,.0f} steps/s"
        )
    return "\n".join(lines)
