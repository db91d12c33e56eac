"""`python -m lca.report <sweep dir | run dirs...> [out=DIR]`"""

from __future__ import annotations

import sys
from pathlib import Path

from lca.cli import split_option
from lca.report.build import build_report


def main(argv: list[str] | None = None) -> int:
    args = list(sys.argv[1:] if argv is None else argv)
    outs, rest = split_option(args, "out")
    paths = [Path(a) for a in rest]
    if not paths:
        print("usage: python -m lca.report <sweep dir | run dirs...> [out=DIR]", file=sys.stderr)
        return 2
    out = Path(outs[0]) if outs else (paths[0] if len(paths) == 1 else Path(".")) / "report"
    index = build_report(paths, out)
    print(f"[lca] report: {index}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
