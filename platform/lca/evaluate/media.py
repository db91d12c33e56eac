"""The pictures a run keeps, made after its evaluation (`eval.videos`, on by default).

Into the run directory: per evaluation cell a clip `clips/<cell>.mp4` (a GIF where MP4
cannot be encoded) with its poster frame `clips/<cell>.png`, and the cell's terrain preview
`terrain/<cell>.png`; the training terrain's preview `terrain/train.png`. (The hardware stage
adds `clips/hw_<task>.mp4`.) The report only embeds these files. Where MuJoCo cannot render,
the clips are skipped, saying why, and the previews show the height map alone.

`clips/media.json` records what they were made from; files made from the same checkpoint,
protocol and settings are kept, the others made again.
"""

from __future__ import annotations

import json
import time
from pathlib import Path

from omegaconf import DictConfig, OmegaConf

from lca.evaluate.clips import cell_setting, gl_missing, save, shoot
from lca.evaluate.policy import final_checkpoint
from lca.evaluate.protocol import cell_config, cell_name
from lca.sim.preview import write_preview
from lca.sim.terrain import generate
from lca.store import atomic_write

CLIPS, TERRAINS = "clips", "terrain"
VERSION = 1  # bump when the pictures change, so that older ones are made again


def _stamp(cfg: DictConfig, checkpoint: Path, rendered: bool) -> dict:
    ev = OmegaConf.to_container(cfg.eval, resolve=True)
    stat = checkpoint.stat()
    return {
        "version": VERSION,
        "checkpoint": [checkpoint.name, stat.st_size, stat.st_mtime_ns],
        "eval": ev,
        "train_terrain": OmegaConf.to_container(cfg.terrain, resolve=True),
        "train_difficulty": OmegaConf.to_container(cfg.difficulty, resolve=True),
        "rendered": rendered,
    }


def expected_files(cfg: DictConfig, rendered: bool) -> list[str]:
    names = [f"{TERRAINS}/train.png"]
    for cell in cfg.eval.cells:
        names.append(f"{TERRAINS}/{cell_name(cell)}.png")
        if rendered:
            names.append(f"{CLIPS}/{cell_name(cell)}.png")
    return names


def make_media(run_dir: Path, cfg: DictConfig, log=print) -> list[Path]:
    """Clips and terrain previews of a trained, evaluated run (see the module docstring).
    Returns the files written (none when `eval.videos` is off or all are up to date)."""
    if not cfg.eval.videos:
        return []
    run_dir = Path(run_dir)
    rendered = not gl_missing(run_dir.name, log)
    checkpoint = final_checkpoint(run_dir)
    stamp = _stamp(cfg, checkpoint, rendered)
    record = run_dir / CLIPS / "media.json"
    if (
        record.exists()
        and json.loads(record.read_text()) == json.loads(json.dumps(stamp))
        and all((run_dir / f).exists() for f in expected_files(cfg, rendered))
    ):
        return []
    record.unlink(missing_ok=True)
    t0 = time.perf_counter()
    written = [
        write_preview(
            run_dir / TERRAINS / "train.png",
            cfg,
            generate(cfg.terrain, cfg.difficulty),
            f"training: terrain={cfg.terrain.name} difficulty={cfg.difficulty.name}",
            tile_size=float(cfg.terrain.tile_size),
        )
    ]
    seconds = float(cfg.eval.video_seconds)
    for cell in cfg.eval.cells:
        name = cell_name(cell)
        t1 = time.perf_counter()
        if rendered:
            setting = cell_setting(cfg, cell, checkpoint, seconds)
            clip = shoot(setting, seconds)
            c, terrain = setting.cfg, setting.terrain
            written.append(save(clip.frames, clip.fps, run_dir / CLIPS / f"{name}.mp4"))
        else:
            c = cell_config(cfg, cell)
            terrain = generate(c.terrain, c.difficulty)
        written.append(
            write_preview(
                run_dir / TERRAINS / f"{name}.png",
                c,
                terrain,
                f"evaluation cell {name}",
                tile_size=float(c.terrain.tile_size),
            )
        )
        if log:
            log(f"[lca] media {run_dir.name} {name}: {time.perf_counter() - t1:.1f} s")
    atomic_write(record, json.dumps(stamp, sort_keys=True))
    if log:
        log(
            f"[lca] media {run_dir.name}: {len(written)} files in "
            f"{time.perf_counter() - t0:.1f} s ({run_dir / CLIPS}, {run_dir / TERRAINS})"
        )
    return written
