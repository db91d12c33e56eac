"""`python -m lca.hardware.scenes [overrides] [out=DIR]`: write the four task scenes (G1 in
its `home` keyframe at the start) as MJCF + binary models, for plain MuJoCo."""

from __future__ import annotations

import sys
from pathlib import Path

import mujoco

from lca.cli import split_option
from lca.config import compose
from lca.paths import assets_dir
from lca.sim.hardware import TASKS, build_task

DEFAULT_OUT = assets_dir() / "hardware"


def main(argv: list[str] | None = None) -> int:
    args = list(sys.argv[1:] if argv is None else argv)
    outs, overrides = split_option(args, "out")
    out = Path(outs[0]) if outs else DEFAULT_OUT
    out.mkdir(parents=True, exist_ok=True)
    cfg = compose(overrides)
    for name in TASKS:
        _, scene = build_task(cfg, name)
        path = out / f"{name}.mjb"
        mujoco.mj_saveModel(scene.model, str(path), None)
        print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
