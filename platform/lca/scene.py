"""Write the compiled scene for a composed config as a binary MuJoCo model.

    python -m lca.scene terrain=stairs_up difficulty=hard out=/tmp/s.mjb

The model holds one G1 in its `home` keyframe at the centre of the first tile; inspect it
with plain MuJoCo (`mujoco.MjModel.from_binary_path`, `python -m mujoco.viewer`).
"""

from __future__ import annotations

import sys
from pathlib import Path

import mujoco

from lca.cli import split_option
from lca.config import compose
from lca.sim.scene import build_scene


def export(overrides: list[str], out: Path) -> Path:
    cfg = compose(overrides)
    scene = build_scene(cfg)
    out.parent.mkdir(parents=True, exist_ok=True)
    mujoco.mj_saveModel(scene.model, str(out), None)
    return out


def main(argv: list[str] | None = None) -> int:
    args = list(sys.argv[1:] if argv is None else argv)
    outs, overrides = split_option(args, "out")
    if len(outs) != 1:
        print("usage: python -m lca.scene [hydra overrides] out=PATH.mjb", file=sys.stderr)
        return 2
    path = export(overrides, Path(outs[0]))
    model = mujoco.MjModel.from_binary_path(str(path))
    ground = f"hfield {model.hfield_nrow[0]}x{model.hfield_ncol[0]}" if model.nhfield else "plane"
    print(
        f"wrote {path} ({path.stat().st_size / 1e6:.1f} MB): nq={model.nq} nu={model.nu} {ground}"
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
