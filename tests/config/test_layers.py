"""The data flow is the import graph: config (and paths) first, then sim -> task -> learn ->
evaluate -> report; a stage imports only stages to its left. Checked on every module's
source, function-level imports included."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

import lca

PACKAGE = Path(lca.__file__).resolve().parent
ORDER = ["config", "sim", "task", "learn", "evaluate", "report"]
BASE = {
    "lca",
    "lca.arrays",
    "lca.paths",
    "lca.cli",
    "lca.store",
    "lca.testhook",
}  # what every stage may use
# evaluation loads a policy from its run directory's files (train_cfg.json, final_<stage>.pt),
# never from the learning stage's code
SKIPPED = {"evaluate": {"learn"}}


def lca_imports(path: Path) -> set[str]:
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            found |= {a.name for a in node.names if a.name.startswith("lca")}
        elif isinstance(node, ast.ImportFrom) and (node.module or "").startswith("lca"):
            found.add(node.module)
    return found


def stage_of(module: str) -> str | None:
    parts = module.split(".")
    return parts[1] if len(parts) > 1 and parts[1] in ORDER else None


@pytest.mark.parametrize("stage", ORDER)
def test_a_stage_imports_only_stages_to_its_left(stage: str) -> None:
    allowed = set(ORDER[: ORDER.index(stage) + 1]) - SKIPPED.get(stage, set())
    bad = []
    for path in sorted((PACKAGE / stage).rglob("*.py")):
        for module in lca_imports(path):
            if module in BASE:
                continue
            if stage_of(module) not in allowed:
                bad.append(f"{path.relative_to(PACKAGE)} imports {module}")
    assert not bad, bad


def test_the_check_sees_a_violation(tmp_path) -> None:
    bad = tmp_path / "bad.py"
    bad.write_text("def f():\n    from lca.task.rewards import REWARD_TERMS\n")
    assert stage_of(next(iter(lca_imports(bad)))) == "task"


@pytest.mark.slow  # a subprocess
def test_a_fresh_process_knows_every_built_in_variant() -> None:
    """Composition alone (no stage imported first) loads every registry's built-ins."""
    import json
    import subprocess
    import sys

    code = (
        "from lca.config import compose\n"
        "from lca.config import registry as r\n"
        "compose(['scale=smoke'])\n"
        "print([len(x.names()) for x in (r.TILES, r.OBS_TERMS, r.REWARD_TERMS, r.ACTORS,"
        " r.ENCODERS, r.EVAL_TERRAINS)])\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    counts = json.loads(out.stdout.strip())
    assert all(n > 0 for n in counts), counts
