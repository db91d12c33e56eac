"""`python -m lca.evaluate run_dir=<dir> [dotlist overrides]`: the paper's protocol on a run.

Writes `results.parquet` (one row per episode) and `summary.csv` (per cell and metric: mean,
standard error and bootstrap CI over units) into the run directory.
"""

from __future__ import annotations

import sys
from pathlib import Path

from lca.cli import split_option
from lca.evaluate.run import evaluate_and_write


def main(argv: list[str] | None = None) -> int:
    args = list(sys.argv[1:] if argv is None else argv)
    run_dirs, overrides = split_option(args, "run_dir")
    if len(run_dirs) != 1:
        print("usage: python -m lca.evaluate run_dir=<dir> [key=value ...]", file=sys.stderr)
        return 2
    summary = evaluate_and_write(Path(run_dirs[0]), overrides)
    print(summary.to_string(index=False))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
