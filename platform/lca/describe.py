"""Print one JSON object describing the composed task.

python -m lca.describe [hydra overrides]
"""

from __future__ import annotations

import json
import sys

from lca.config import compose
from lca.task.spec import describe_task


def main(argv: list[str] | None = None) -> int:
    cfg = compose(list(sys.argv[1:] if argv is None else argv))
    print(json.dumps(describe_task(cfg), indent=2))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
