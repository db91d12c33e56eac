"""Dispatch `python -m lca.bench <name> [--json] [overrides]` to a benchmark module."""

from __future__ import annotations

import argparse
import importlib
import json
import sys

from lca.paths import reports_dir

BENCHMARKS = (
    "floor",
    "sim",
    "env",
    "train",
    "learn",
    "walk",
    "levers",
    "clips",
    "report",
    "evaluate",
    "hardware",
)


def result_name(name: str, result: dict) -> str:
    """`<name>.json`, or `<name>_warp.json` when the benchmark ran on the MuJoCo-Warp backend
    (its result says so): `python -m lca.experiment --dry-run` reads the rate of the backend
    it plans for. A result may name its own variant (`variant`: the walk on terrain), so
    that it does not overwrite the plain one."""
    stem = f"{name}_{result['variant']}" if result.get("variant") else name
    return f"{stem}_warp.json" if result.get("backend") == "warp" else f"{stem}.json"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m lca.bench")
    parser.add_argument("name", choices=BENCHMARKS)
    parser.add_argument("--json", action="store_true", help="print one JSON object only")
    parser.add_argument("overrides", nargs="*", help="Hydra overrides, e.g. terrain=flat")
    args = parser.parse_intermixed_args(argv)
    module = importlib.import_module(f"lca.bench.{args.name}")
    result = module.run(args.overrides, log=None if args.json else print)
    save_dir = reports_dir() / "bench"
    save_dir.mkdir(parents=True, exist_ok=True)
    (save_dir / result_name(args.name, result)).write_text(json.dumps(result, indent=2))
    if args.json:
        print(json.dumps(result))
    else:
        print(module.table(result))
    return 0


if __name__ == "__main__":
    sys.exit(main())
