"""`python -m lca.hardware run_dir=<dir> [key=value ...]`: run the hardware-style tasks on a
trained run (writes <run>/hardware.csv, and with eval.videos a clip per task in <run>/clips/)
and print the per-task table."""

from __future__ import annotations

import sys
from pathlib import Path

from lca.cli import split_option
from lca.evaluate.hardware import run_hardware
from lca.evaluate.policy import load_run_config
from lca.report.hardware_table import hardware_rows


def main(argv: list[str] | None = None) -> int:
    args = list(sys.argv[1:] if argv is None else argv)
    run_dirs, overrides = split_option(args, "run_dir")
    if len(run_dirs) != 1:
        print("usage: python -m lca.hardware run_dir=<dir> [key=value ...]", file=sys.stderr)
        return 2
    run_dir = Path(run_dirs[0])
    cfg = load_run_config(run_dir, overrides)
    trials = run_hardware(run_dir, cfg)
    print(hardware_rows(trials).to_string(index=False))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
