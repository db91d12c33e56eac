"""What the pictures made after evaluation cost (issue 14): `make_media` on the shipped walking
policy (assets/policies/blind_flat, a scale=cpu run, copied to a temporary run directory):
the training terrain's preview, then per evaluation cell (the default four) the clip
(`eval.video_seconds`, 4 s at 25 fps by default) and the cell's terrain preview.
"""

from __future__ import annotations

import os
import re
import shutil
import tempfile
import time
from pathlib import Path

from lca.evaluate.media import make_media
from lca.evaluate.policy import load_run_config
from lca.paths import assets_dir
from lca.sim.render import gl_unavailable

SHIPPED = assets_dir() / "policies" / "blind_flat"
CELL_LINE = re.compile(r"\[lca\] media \S+ (\S+): ([\d.]+) s")


def run(overrides: list[str], log=print) -> dict:
    reason = gl_unavailable()
    if reason:
        raise RuntimeError(f"MuJoCo cannot render here: {reason}")
    with tempfile.TemporaryDirectory() as tmp:
        run_dir = Path(tmp) / "blind_flat"
        shutil.copytree(SHIPPED, run_dir)
        cfg = load_run_config(run_dir, ["eval.videos=true", *overrides])
        lines: list[str] = []

        def keep(line: str) -> None:
            lines.append(line)
            if log:
                log(line)

        start = time.perf_counter()
        files = make_media(run_dir, cfg, log=keep)
        total = time.perf_counter() - start
        sizes = {f.name: f.stat().st_size for f in files}
    cells = {m.group(1): float(m.group(2)) for m in map(CELL_LINE.match, lines) if m}
    clips = [n for n in sizes if n.endswith((".mp4", ".gif"))]
    return {
        "total_s": round(total, 1),
        "cells_s": cells,
        "train_preview_s": round(total - sum(cells.values()), 1),
        "video_seconds": float(cfg.eval.video_seconds),
        "clips": len(clips),
        "clip_bytes": sum(sizes[n] for n in clips),
        "backend": os.environ.get("MUJOCO_GL", "glfw"),
        "cores": os.cpu_count(),
    }


def table(result: dict) -> str:
    rows = ["| step | seconds |", "|---|---:|"]
    rows.append(f"| training terrain preview | {result['train_preview_s']:.1f} |")
    for cell, seconds in result["cells_s"].items():
        rows.append(f"| {cell}: clip + terrain preview | {seconds:.1f} |")
    rows.append(f"| **total** | **{result['total_s']:.1f}** |")
    return "\n".join(rows) + (
        f"\n\n{result['clips']} clips of {result['video_seconds']:g} s, "
        f"{result['clip_bytes'] / 1e6:.2f} MB in all; MUJOCO_GL={result['backend']}, "
        f"{result['cores']} cores"
    )
