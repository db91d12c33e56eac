"""The hardware-style tasks' trials with the static ground as a heightfield (the baseline)
against rotated boxes (`hardware.representation=strips`), timed task by task in one run:

    python -m lca.bench hardware [shipped=one_mlp] [hardware.trials=5 ...]

`shipped` names a folder under assets/policies/ (a policy with a map runs the deployment
cameras, whose ray casts are what the representation changes); the rest are overrides of its
config. No clips are filmed. Both representations run the same trials with the same seeds.
"""

from __future__ import annotations

import shutil
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import torch

from lca.bench.timing import split_params
from lca.config import set_torch_threads
from lca.evaluate.hardware import run_hardware
from lca.evaluate.policy import load_run_config
from lca.paths import assets_dir

DEFAULTS = {"shipped": "one_mlp"}
REPRESENTATIONS = ("heightfield", "strips")  # baseline first


def run(overrides: list[str], log: Callable[[str], None] | None = print) -> dict:
    params, extra = split_params(overrides, DEFAULTS)
    quiet = (lambda _: None) if log is None else log
    result: dict = {"shipped": params["shipped"], "overrides": extra, "tasks": {}}
    with tempfile.TemporaryDirectory() as tmp:
        run_dir = Path(tmp, params["shipped"])
        shutil.copytree(assets_dir() / "policies" / params["shipped"], run_dir)
        base = load_run_config(run_dir, [*extra, "eval.videos=false"])
        set_torch_threads(int(base.torch_threads))
        result["threads"] = torch.get_num_threads()
        for name in base.hardware.tasks:
            row = result["tasks"][name] = {}
            for representation in REPRESENTATIONS:
                cfg = load_run_config(
                    run_dir,
                    [
                        *extra,
                        "eval.videos=false",
                        f"hardware.tasks=[{name}]",
                        f"hardware.representation={representation}",
                    ],
                )
                t0 = time.perf_counter()
                trials = run_hardware(run_dir, cfg, log=None)
                row[f"{representation}_s"] = time.perf_counter() - t0
                row[f"{representation}_successes"] = int(trials.success.sum())
                quiet(
                    f"[bench] {name} {representation}: {row[f'{representation}_s']:.1f} s, "
                    f"{row[f'{representation}_successes']}/{len(trials)} successes"
                )
    for key in ("heightfield_s", "strips_s"):
        result[key] = sum(row[key] for row in result["tasks"].values())
    result["speedup"] = result["heightfield_s"] / result["strips_s"]
    return result


def table(result: dict) -> str:
    rows = [
        f"hardware-style trials of `{result['shipped']}` {' '.join(result['overrides'])} "
        f"({result['threads']} torch threads)",
        "| task | heightfield (s) | strips (s) | ratio | successes (heightfield / strips) |",
        "|---|---:|---:|---:|---|",
    ]
    for name, row in result["tasks"].items():
        rows.append(
            f"| {name} | {row['heightfield_s']:.1f} | {row['strips_s']:.1f} | "
            f"{row['heightfield_s'] / row['strips_s']:.1f}x | "
            f"{row['heightfield_successes']} / {row['strips_successes']} |"
        )
    rows.append(
        f"| **all** | **{result['heightfield_s']:.1f}** | **{result['strips_s']:.1f}** | "
        f"**{result['speedup']:.1f}x** | |"
    )
    return "\n".join(rows)
