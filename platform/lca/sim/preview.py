"""Terrain previews (PNG): check a terrain and difficulty before training on them.

Left, the whole heightfield as a shaded height map (every tile labelled with its kind and
riser or block heights); right, a rendered close-up of the robot on the first tile for scale
(left out, saying why, where MuJoCo cannot render).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib import cm, colors
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.patches import Rectangle
from omegaconf import DictConfig

from lca.sim import render
from lca.sim.terrain import Terrain, Tile
from lca.store import write_atomically

MAP_PIXELS = 800  # height-map samples per side at most


def tile_label(tile: Tile) -> str:
    p = tile.params
    if "riser" in p:
        return f"{tile.kind.replace('stairs_', '')}\nriser {p['riser']:.2f} m"
    if "low" in p:
        return f"uneven\n{p['low']:.2f}-{p['high']:.2f} m"
    return tile.kind


def _height_map(fig: Figure, ax, terrain: Terrain, tile_size: float | None) -> None:
    step = max(1, int(np.ceil(max(terrain.heights.shape) / MAP_PIXELS)))
    h = terrain.heights[::step, ::step]
    res = terrain.resolution * step
    (x0, y0), (sx, sy) = terrain.origin, terrain.size
    low, high = float(h.min()), float(h.max())
    pad = max(0.0, 0.5 - (high - low)) / 2  # a flat field is not a scale of millimetres
    norm = colors.Normalize(low - pad, high + pad)
    shaded = colors.LightSource(azdeg=315, altdeg=40).shade(
        h, cmap=cm.terrain, norm=norm, blend_mode="soft", dx=res, dy=res
    )
    ax.imshow(shaded, origin="lower", extent=(x0, x0 + sx, y0, y0 + sy))
    fig.colorbar(cm.ScalarMappable(norm=norm, cmap=cm.terrain), ax=ax, label="height (m)")
    for tile in terrain.tiles:
        ax.text(
            *tile.centre,
            tile_label(tile),
            ha="center",
            va="center",
            fontsize=7,
            bbox={"facecolor": "white", "alpha": 0.6, "linewidth": 0, "pad": 1},
        )
        if tile_size:
            corner = (tile.centre[0] - tile_size / 2, tile.centre[1] - tile_size / 2)
            ax.add_patch(Rectangle(corner, tile_size, tile_size, fill=False, lw=0.5, alpha=0.5))
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")


def write_preview(
    path: Path,
    cfg: DictConfig,
    terrain: Terrain,
    title: str = "",
    decorate: render.Decorate | None = None,
    tile_size: float | None = None,
) -> Path:
    """The preview of `terrain` (scene settings from `cfg`) as a PNG at `path`."""
    fig = Figure(figsize=(11.0, 4.2), dpi=100, layout="constrained")
    FigureCanvasAgg(fig)
    reason = render.gl_unavailable()
    left, right = fig.subplots(1, 2, width_ratios=[1.0, 1.25])
    _height_map(fig, left, terrain, tile_size)
    if reason is None:
        right.imshow(render.close_up(cfg, terrain, decorate))
        right.set_title("first tile, robot in its home pose", fontsize=9)
    else:
        right.text(0.5, 0.5, f"no 3-D view: {reason}", ha="center", va="center", wrap=True)
    right.set_axis_off()
    if title:
        fig.suptitle(title)
    return write_atomically(path, lambda tmp: fig.savefig(tmp, format="png"))
