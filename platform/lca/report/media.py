"""The dashboard's pictures: the clips and terrain previews that the evaluation stages left in
each run directory (`clips/`, `terrain/`), copied into the report's `media/` folder and laid
out as HTML with relative paths, so the page works from file:// with no network. The report
renders nothing: a run without these files shows none.

Files are named by their content, so a terrain that many runs share is stored and shown once.
"""

from __future__ import annotations

import hashlib
import html
import shutil
from dataclasses import dataclass
from pathlib import Path

from omegaconf import OmegaConf

from lca.report.collect import RunRecord, row_key

MEDIA = "media"
VIDEO_SUFFIXES = (".mp4", ".gif")
WIDTH, HEIGHT = 320, 240  # the clips' size (lca.sim.render)


@dataclass
class Picture:
    src: str  # relative to the report folder
    caption: str
    poster: str = ""  # for a video


def _copy(path: Path, out_dir: Path) -> str:
    digest = hashlib.sha1(path.read_bytes()).hexdigest()[:12]
    name = f"{path.stem}-{digest}{path.suffix}"
    target = out_dir / MEDIA / name
    if not target.exists():
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(path, target)
    return f"{MEDIA}/{name}"


def _cells(run: RunRecord) -> list[str]:
    cfg = OmegaConf.load(run.path / "config.yaml")
    return [f"{c.terrain}-{c.difficulty}" for c in cfg.get("eval", {}).get("cells", [])]


def run_clips(run: RunRecord, out_dir: Path) -> list[Picture]:
    """The run's clips, evaluation cells in the config's order, then hardware tasks."""
    folder = run.path / "clips"
    if not folder.is_dir():
        return []
    clips = [p for p in folder.iterdir() if p.suffix in VIDEO_SUFFIXES and p.is_file()]
    order = {name: i for i, name in enumerate(_cells(run))}
    clips.sort(key=lambda p: (p.stem.startswith("hw_"), order.get(p.stem, len(order)), p.stem))
    pictures = []
    for clip in clips:
        poster = clip.with_suffix(".png")
        caption = f"hardware: {clip.stem[3:]}" if clip.stem.startswith("hw_") else clip.stem
        pictures.append(
            Picture(
                _copy(clip, out_dir), caption, _copy(poster, out_dir) if poster.exists() else ""
            )
        )
    return pictures


def _figure(picture: Picture) -> str:
    src, caption = html.escape(picture.src), html.escape(picture.caption)
    if picture.src.endswith(".gif"):
        body = f'<img src="{src}" width="{WIDTH}" height="{HEIGHT}" alt="{caption}">'
    else:
        poster = f' poster="{html.escape(picture.poster)}"' if picture.poster else ""
        body = (
            f'<video src="{src}"{poster} width="{WIDTH}" height="{HEIGHT}" controls muted '
            f'loop playsinline preload="metadata"></video>'
        )
    return f'<figure class="clip">{body}<figcaption>{caption}</figcaption></figure>'


def clips_section(runs: list[RunRecord], out_dir: Path) -> str:
    blocks = []
    for run in sorted(runs, key=lambda r: (row_key(r.label), r.seed, r.name)):
        pictures = run_clips(run, out_dir)
        if pictures:
            title = f"{run.label}, seed {run.seed} ({run.name})"
            figures = "".join(_figure(p) for p in pictures)
            blocks.append(f'<h3>{html.escape(title)}</h3><div class="clips">{figures}</div>')
    if not blocks:
        return ""
    return (
        '<h2 id="clips">Rollouts</h2>\n<p>One unit per evaluation cell, seeded like the cell\'s '
        "first round, and the first trial of each hardware-style task, on the run's final "
        "policy. Overlay: command (yellow) against measured (cyan) base velocity; the chart is "
        "the forward speed over the last 3 s.</p>\n" + "\n".join(blocks)
    )


def terrains_section(runs: list[RunRecord], out_dir: Path) -> str:
    """Each distinct training and evaluation terrain once, captioned with who uses it."""
    shown: dict[str, list] = {}  # src -> [caption, users]
    for run in sorted(runs, key=lambda r: (row_key(r.label), r.seed, r.name)):
        folder = run.path / "terrain"
        if not folder.is_dir():
            continue
        names = ["train", *_cells(run)]
        for name in names:
            path = folder / f"{name}.png"
            if path.is_file():
                src = _copy(path, out_dir)
                caption = "training" if name == "train" else f"evaluation cell {name}"
                entry = shown.setdefault(src, [caption, []])
                if name == "train":
                    entry[1].append(run.name)
    if not shown:
        return ""
    figures = []
    for src, (caption, users) in shown.items():
        text = f"{caption} ({', '.join(users)})" if users else caption
        figures.append(
            f'<figure class="terrain"><img src="{html.escape(src)}" alt="{html.escape(text)}">'
            f"<figcaption>{html.escape(text)}</figcaption></figure>"
        )
    return (
        '<h2 id="terrains">Terrains</h2>\n<p>Height maps of the generated terrains with a '
        "rendered close-up of the first tile, made when the runs were evaluated.</p>\n"
        + "\n".join(figures)
    )
