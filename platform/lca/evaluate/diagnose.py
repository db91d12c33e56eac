"""What a policy does with each command, and what the paper's reward pays it for doing it.

    python -m lca.evaluate.diagnose run_dir=<dir> [checkpoint=<path>] [cell=flat-medium]
        [units=16] [steps=300]

The deterministic policy runs on an evaluation cell (default the flat one; the protocol's
observation noise, no randomisation) under each command of `COMMANDS`, held fixed. Per
command it reports the base velocity it reaches (mean over the units' steps after the first
second, base frame) and every reward term per second of simulated time under the paper's
table (no curriculum, no clip), over the steps before a unit's first termination. A
flat-cell evaluation sees only forward commands; this shows whether a walker follows what it
is told (zero: stand; backward, sideways, turn) and which terms of the table it pays for its
posture. On a terrain cell (`cell=stairs-medium`) it shows what crossing that terrain costs
against standing at the spawn, and `alive_s` how long the units last there.

Writes `<run>/diagnosis/commands.csv` and `terms.csv` (another cell than the flat one:
`<run>/diagnosis/<cell>/`) and prints both as tables.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import torch

from lca.arrays import like, to_numpy
from lca.cli import split_option
from lca.config import ConfigError
from lca.evaluate.config import EvalCell, parse_cell
from lca.evaluate.policy import final_checkpoint, load_policy, load_run_config
from lca.evaluate.protocol import cell_config, cell_name
from lca.evaluate.rollout import rollout, start
from lca.store import write_atomically
from lca.task.env import LocomotionEnv

# (u_x m/s, u_y m/s, u_yaw rad/s): inside the paper's training ranges
COMMANDS = {
    "forward 0.45": (0.45, 0.0, 0.0),
    "forward 0.2": (0.2, 0.0, 0.0),
    "stand": (0.0, 0.0, 0.0),
    "backward 0.4": (-0.4, 0.0, 0.0),
    "left 0.25": (0.0, 0.25, 0.0),
    "turn 0.4": (0.0, 0.0, 0.4),
}
SETTLE_S = 1.0  # the velocity is averaged after this, once the gait has started


FLAT = EvalCell("flat", "medium")


def diagnosis_env(run_dir: Path, units: int, steps: int, cell: EvalCell = FLAT) -> tuple:
    """The run's config turned into `cell` with `units` units and `steps` steps."""
    cfg = load_run_config(run_dir)
    cfg.eval.units, cfg.eval.steps = int(units), int(steps)
    env = LocomotionEnv(cell_config(cfg, cell))
    env.set_perception(False)
    return cfg, env


@torch.inference_mode()
def hold_command(
    env: LocomotionEnv, policy, command: tuple, steps: int, seed: int
) -> tuple[dict, dict]:
    """(the mean base velocity after SETTLE_S, each reward term per second) of `steps` steps
    with every unit told `command`, counted until a unit's first termination."""
    env.reseed(seed)
    obs = start(env, policy)
    alive = np.ones(env.num_envs, dtype=bool)
    settle = round(SETTLE_S / env.dt)
    velocity, counted = np.zeros(3), 0
    sums = {name: 0.0 for name in env.reward_manager.episode_sums}
    before = {name: to_numpy(s).copy() for name, s in env.reward_manager.episode_sums.items()}
    command = like(np.asarray(command, dtype=np.float64), env.commands.value)
    env.commands.value[:] = command
    env.commands.time_left[:] = math.inf
    alive_steps = 0
    for step, m in rollout(env, policy, obs, steps):
        alive &= ~(m["terminated"] | m["time_out"])
        for name, s in env.reward_manager.episode_sums.items():
            s = to_numpy(s)
            sums[name] += float(np.sum((s - before[name])[alive]))
            before[name] = s.copy()
        alive_steps += int(alive.sum())
        if step >= settle and alive.any():
            velocity += np.append(m["base_vel"][alive], m["yaw_rate"][alive, None], 1).sum(0)
            counted += int(alive.sum())
        env.commands.value[:] = command
        if not alive.any():
            break
    response = dict(zip(("v_x", "v_y", "yaw_rate"), velocity / max(counted, 1), strict=True))
    response["alive_s"] = alive_steps * env.dt / env.num_envs
    per_second = {name: total / max(alive_steps * env.dt, 1e-9) for name, total in sums.items()}
    return response, per_second


def diagnose(
    run_dir: Path,
    checkpoint: Path | None = None,
    units: int = 16,
    steps: int = 300,
    cell: EvalCell = FLAT,
) -> tuple[pd.DataFrame, pd.DataFrame]:
    """(commands: one row per command, with the reached velocity; terms: reward per second,
    one row per term and a `total` row, one column per command)."""
    cfg, env = diagnosis_env(run_dir, units, steps, cell)
    policy = load_policy(cfg, env, checkpoint or final_checkpoint(run_dir))
    rows, terms = [], {}
    for label, command in COMMANDS.items():
        response, per_second = hold_command(env, policy, command, steps, int(cfg.eval.seed))
        u_x, u_y, u_yaw = command
        rows.append({"command": label, "u_x": u_x, "u_y": u_y, "u_yaw": u_yaw, **response})
        terms[label] = per_second
    table = pd.DataFrame(terms)
    table.loc["total"] = table.sum()
    return pd.DataFrame(rows), table.rename_axis("term")


def main(argv: list[str] | None = None) -> int:
    args = list(sys.argv[1:] if argv is None else argv)
    run_dirs, args = split_option(args, "run_dir")
    checkpoints, args = split_option(args, "checkpoint")
    units, args = split_option(args, "units")
    steps, args = split_option(args, "steps")
    cells, args = split_option(args, "cell")
    if len(run_dirs) != 1 or args:
        print(__doc__.strip().splitlines()[2], file=sys.stderr)
        return 2
    run_dir = Path(run_dirs[0])
    try:
        cell = parse_cell(cells[-1]) if cells else FLAT
    except ConfigError as error:
        print(error, file=sys.stderr)
        return 2
    commands, terms = diagnose(
        run_dir,
        Path(checkpoints[-1]) if checkpoints else None,
        int(units[-1]) if units else 16,
        int(steps[-1]) if steps else 300,
        cell,
    )
    name = cell_name(cell)
    out = run_dir / "diagnosis"
    if name != cell_name(FLAT):  # a flat diagnosis keeps its path; others get their own folder
        out = out / name
    write_atomically(out / "commands.csv", lambda p: commands.to_csv(p, index=False), ".csv")
    write_atomically(out / "terms.csv", terms.to_csv, ".csv")
    print(commands.round(3).to_string(index=False))
    print(f"\nreward per second under the paper's table ({name}, deterministic policy):")
    print(terms.round(3).to_string())
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
