"""What the pictures made after evaluation cost (issue 14): `make_media` on the shipped walking
policy (assets/policies/blind_flat, a scale=cpu run, copied to a temporary run directory):
the training terrain's preview, then per evaluation cell (the default four) the clip
(`eval.video_seconds`, 4 s at 25 fps by default) and the cell's terrain preview.

Then, per cell, the same recording (`frames=40` frames) filmed twice: the ground drawn as a
crop of the terrain's samples (the baseline: a heightfield of 2 cm triangles) and as
`render.window` draws it (the boxes that meet the path), in ms per frame.
"""

from __future__ import annotations

import os
import re
import shutil
import tempfile
import time
from pathlib import Path

from lca.bench.timing import split_params
from lca.evaluate.clips import cell_setting, film, record
from lca.evaluate.media import make_media
from lca.evaluate.policy import final_checkpoint, load_run_config
from lca.paths import assets_dir
from lca.sim import render
from lca.sim.render import gl_unavailable

SHIPPED = assets_dir() / "policies" / "blind_flat"
DEFAULTS = {"frames": "40"}
CELL_LINE = re.compile(r"\[lca\] media \S+ (\S+): ([\d.]+) s")


def run(overrides: list[str], log=print) -> dict:
    reason = gl_unavailable()
    if reason:
        raise RuntimeError(f"MuJoCo cannot render here: {reason}")
    params, overrides = split_params(overrides, DEFAULTS)
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
        frames = frame_costs(run_dir, cfg, int(params["frames"]))
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
        "frames": frames,
        "frame_speedup": sum(f["crop_ms"] for f in frames.values())
        / sum(f["window_ms"] for f in frames.values()),
    }


def frame_costs(run_dir: Path, cfg, frames: int) -> dict[str, dict[str, float]]:
    """ms per frame of each cell's first `frames` frames, filmed with each ground (the
    render model's build included, as a clip pays it)."""
    out = {}
    for cell in cfg.eval.cells:
        setting = cell_setting(cfg, cell, final_checkpoint(run_dir), float(cfg.eval.video_seconds))
        rec = record(setting.env, setting.policy, frames)
        costs = {}
        for name, ground in (("crop", render.crop), ("window", render.window)):
            t0 = time.perf_counter()
            film(setting.cfg, setting.terrain, rec, setting.label, ground=ground)
            costs[f"{name}_ms"] = round((time.perf_counter() - t0) / len(rec) * 1e3, 1)
        out[setting.label] = costs
    return out


def table(result: dict) -> str:
    rows = ["| step | seconds |", "|---|---:|"]
    rows.append(f"| training terrain preview | {result['train_preview_s']:.1f} |")
    for cell, seconds in result["cells_s"].items():
        rows.append(f"| {cell}: clip + terrain preview | {seconds:.1f} |")
    rows.append(f"| **total** | **{result['total_s']:.1f}** |")
    rows += ["", "| cell | ground as samples (ms/frame) | as boxes (ms/frame) | ratio |"]
    rows.append("|---|---:|---:|---:|")
    for cell, f in result["frames"].items():
        ratio = f["crop_ms"] / f["window_ms"]
        rows.append(f"| {cell} | {f['crop_ms']:.1f} | {f['window_ms']:.1f} | {ratio:.2f}x |")
    rows.append(f"| **all** | | | **{result['frame_speedup']:.2f}x** |")
    return "\n".join(rows) + (
        f"\n\n{result['clips']} clips of {result['video_seconds']:g} s, "
        f"{result['clip_bytes'] / 1e6:.2f} MB in all; MUJOCO_GL={result['backend']}, "
        f"{result['cores']} cores"
    )
