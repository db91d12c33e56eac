"""Write the compiled scene for a composed config as a binary MuJoCo model, or a preview.

    python -m lca.scene terrain=stairs_up difficulty=hard out=/tmp/s.mjb
    python -m lca.scene terrain=uneven difficulty=hard preview=terrain.png

The model holds one G1 in its `home` keyframe at the centre of the first tile; inspect it
with plain MuJoCo (`mujoco.MjModel.from_binary_path`, `python -m mujoco.viewer`). The
preview shows the generated terrain as a height map, every tile labelled, beside a rendered
close-up of the robot on the first tile: check a difficulty before training on it.
"""

from __future__ import annotations

import sys
from pathlib import Path

import mujoco

from lca.cli import split_option
from lca.config import compose
from lca.sim.preview import write_preview
from lca.sim.scene import build_scene
from lca.sim.terrain import generate

USAGE = "usage: python -m lca.scene [hydra overrides] [out=PATH.mjb] [preview=PATH.png]"


def export(overrides: list[str], out: Path) -> Path:
    cfg = compose(overrides)
    scene = build_scene(cfg)
    out.parent.mkdir(parents=True, exist_ok=True)
    mujoco.mj_saveModel(scene.model, str(out), None)
    return out


def preview(overrides: list[str], out: Path) -> Path:
    cfg = compose(overrides)
    title = f"terrain={cfg.terrain.name} difficulty={cfg.difficulty.name}"
    terrain = generate(cfg.terrain, cfg.difficulty)
    return write_preview(out, cfg, terrain, title, tile_size=float(cfg.terrain.tile_size))


def main(argv: list[str] | None = None) -> int:
    args = list(sys.argv[1:] if argv is None else argv)
    outs, overrides = split_option(args, "out")
    previews, overrides = split_option(overrides, "preview")
    if len(outs) > 1 or len(previews) > 1 or not (outs or previews):
        print(USAGE, file=sys.stderr)
        return 2
    if outs:
        path = export(overrides, Path(outs[0]))
        model = mujoco.MjModel.from_binary_path(str(path))
        ground = (
            f"hfield {model.hfield_nrow[0]}x{model.hfield_ncol[0]}" if model.nhfield else "plane"
        )
        size = path.stat().st_size / 1e6
        print(f"wrote {path} ({size:.1f} MB): nq={model.nq} nu={model.nu} {ground}")
    if previews:
        path = preview(overrides, Path(previews[0]))
        print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
