"""The terrain as the boxes representation builds it: each tile's cells (`Tile.cells`)
merged into as few boxes as cover them, and the exact height of those boxes' tops.

A box's top is its cell's height and every box reaches down to one common base, so risers are
vertical faces and a pit's walls are solid. Tiles without cells (a plugin's slopes) become a
heightfield of their own, built from the tile's samples.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from lca.arrays import Array, arrays, device_of, namespace
from lca.sim.strips import BASE_DEPTH
from lca.sim.terrain import Terrain, Tile


@dataclass
class Box:
    x: tuple[float, float]  # world x from, to
    y: tuple[float, float]
    top: float


def rectangles(heights: np.ndarray) -> list[tuple[int, int, int, int]]:
    """Cover a grid of cell heights with rectangles of equal height, greedily: from each
    uncovered cell in row-major order, run right, then extend the run down while whole.
    Returns (row0, row1, col0, col1), ends exclusive. Concentric stairs give 4 per ring."""
    nrow, ncol = heights.shape
    covered = np.zeros(heights.shape, bool)
    out = []
    for r in range(nrow):
        for c in range(ncol):
            if covered[r, c]:
                continue
            h = heights[r, c]
            c1 = c + 1
            while c1 < ncol and not covered[r, c1] and heights[r, c1] == h:
                c1 += 1
            r1 = r + 1
            while r1 < nrow and not covered[r1, c:c1].any() and (heights[r1, c:c1] == h).all():
                r1 += 1
            covered[r:r1, c:c1] = True
            out.append((r, r1, c, c1))
    return out


def tile_boxes(tile: Tile) -> list[Box]:
    edges, heights = tile.cells
    cx, cy = tile.centre
    return [
        Box((cx + edges[c0], cx + edges[c1]), (cy + edges[r0], cy + edges[r1]), heights[r0, c0])
        for r0, r1, c0, c1 in rectangles(heights)
    ]


def terrain_boxes(terrain: Terrain) -> list[Box]:
    """Every tile's boxes; those that meet `terrain.window` where it is set."""
    boxes = [box for tile in terrain.tiles if tile.cells is not None for box in tile_boxes(tile)]
    if terrain.window is None:
        return boxes
    (x0, y0), (x1, y1) = terrain.window
    return [b for b in boxes if b.x[1] >= x0 and b.x[0] <= x1 and b.y[1] >= y0 and b.y[0] <= y1]


def base_height(terrain: Terrain) -> float:
    return min(0.0, float(terrain.heights.min())) - BASE_DEPTH


def add_boxes(spec: mujoco.MjSpec, terrain: Terrain, rgba: list, collide: dict) -> None:
    """Every tile with cells as boxes (named terrain_box<i>); the others as heightfields."""
    base = base_height(terrain)
    for i, box in enumerate(terrain_boxes(terrain)):
        half = [(box.x[1] - box.x[0]) / 2, (box.y[1] - box.y[0]) / 2, (box.top - base) / 2]
        centre = [(box.x[0] + box.x[1]) / 2, (box.y[0] + box.y[1]) / 2, (box.top + base) / 2]
        spec.worldbody.add_geom(
            name=f"terrain_box{i}",
            type=mujoco.mjtGeom.mjGEOM_BOX,
            size=half,
            pos=centre,
            rgba=rgba,
            **collide,
        )
    for tile in terrain.tiles:
        if tile.cells is None:
            _add_tile_field(spec, terrain, tile, base, rgba, collide)


def _add_tile_field(spec, terrain: Terrain, tile: Tile, base: float, rgba, collide) -> None:
    """One tile's samples (its far edge included) as a heightfield of its own."""
    res, half = terrain.resolution, terrain.tile_size / 2
    r0 = int(round((tile.centre[1] - half - terrain.origin[1]) / res))
    c0 = int(round((tile.centre[0] - half - terrain.origin[0]) / res))
    n = int(round(terrain.tile_size / res)) + 1
    h = terrain.heights[r0 : r0 + n, c0 : c0 + n]
    low = float(h.min())
    span = max(float(np.ptp(h)), 1e-3)
    name = f"terrain_tile{tile.row}_{tile.col}"
    spec.add_hfield(
        name=name,
        size=[half, half, span, low - base],
        nrow=n,
        ncol=n,
        userdata=((h - low) / span).astype(np.float32).ravel(),
    )
    spec.worldbody.add_geom(
        name=name,
        type=mujoco.mjtGeom.mjGEOM_HFIELD,
        hfieldname=name,
        pos=[tile.centre[0], tile.centre[1], low],
        rgba=rgba,
        **collide,
    )


@dataclass
class CellGrid:
    """Every tile's cells on one world grid: `heights[j, i]` holds between xs[i-1] and xs[i]
    and ys[j-1] and ys[j] (index 0 and the last: outside the tiles, flat ground at 0); NaN
    on a tile without cells. A lookup needs no binary search: `x_bucket[k]` is the cell at
    the start of the k-th `resolution`-wide bucket from `xs[0] - resolution` (every line lies
    on a bucket boundary), and a comparison with the cell's lines settles rounding there."""

    xs: np.ndarray
    ys: np.ndarray
    heights: np.ndarray
    any_field: bool
    resolution: float
    x_bucket: np.ndarray
    y_bucket: np.ndarray


def _buckets(lines: np.ndarray, resolution: float) -> np.ndarray:
    """Cell index of each bucket, from one bucket before the first line (cell 0) to one
    starting at the last line (past every line)."""
    n = int(round((lines[-1] - lines[0]) / resolution)) + 2
    centres = lines[0] + resolution * (np.arange(n) - 0.5)
    return np.searchsorted(lines, centres, side="right")


def cell_grid(terrain: Terrain) -> CellGrid:
    half = terrain.tile_size / 2
    xs, ys = [], []
    for tile in terrain.tiles:
        edges = tile.cells[0] if tile.cells is not None else np.array([-half, half])
        xs.append(tile.centre[0] + edges)
        ys.append(tile.centre[1] + edges)
    xs = np.unique(np.round(np.concatenate(xs), 9))
    ys = np.unique(np.round(np.concatenate(ys), 9))
    heights = np.zeros((len(ys) + 1, len(xs) + 1))
    mx, my = (xs[:-1] + xs[1:]) / 2, (ys[:-1] + ys[1:]) / 2
    for tile in terrain.tiles:
        cols = np.flatnonzero(np.abs(mx - tile.centre[0]) < half)
        rows = np.flatnonzero(np.abs(my - tile.centre[1]) < half)
        block = np.ix_(rows + 1, cols + 1)
        if tile.cells is None:
            heights[block] = np.nan
            continue
        edges, cell_heights = tile.cells
        i = np.searchsorted(edges, mx[cols] - tile.centre[0]) - 1
        j = np.searchsorted(edges, my[rows] - tile.centre[1]) - 1
        heights[block] = cell_heights[np.ix_(j, i)]
    res = terrain.resolution
    any_field = bool(np.isnan(heights).any())
    return CellGrid(xs, ys, heights, any_field, res, _buckets(xs, res), _buckets(ys, res))


def _cell_index(x: Array, lookup: tuple, xp) -> Array:
    """Index of the cell holding x: 0 before the first line, len(lines) past the last."""
    start, inverse, bucket, lower, upper = lookup
    # truncation, not floor: they differ only below 0, which the clip maps to bucket 0 anyway
    k = xp.clip(xp.astype((x - start) * inverse, xp.int64), min=0, max=bucket.shape[0] - 1)
    i = xp.take(bucket, k)
    i += xp.astype(x >= xp.take(upper, i), xp.int64)
    i -= xp.astype(x < xp.take(lower, i), xp.int64)
    return i


def _lookup(lines: np.ndarray, bucket: np.ndarray, resolution: float, on, xp) -> tuple:
    """(first bucket's start, 1 / resolution, bucket cells, each cell's lower and upper
    line): the outer cells' outer lines are infinite, so a point past every line stays."""
    lower, upper = np.insert(lines, 0, -np.inf), np.append(lines, np.inf)
    start = float(lines[0] - resolution)
    return (start, 1.0 / resolution, on(bucket, xp.int64), on(lower), on(upper))


def cell_height_at(terrain: Terrain, x: Array, y: Array) -> Array:
    """Height of the boxes' tops at world points (NumPy or torch), a heightfield tile's
    surface where there is one. On an edge, the cell on the +x / +y side."""
    x, y = arrays(x, y)
    xp = namespace(x, y)
    x, y = xp.broadcast_arrays(x, y)
    key = ("cells", type(x).__module__, str(device_of(x)), str(x.dtype))
    if key not in terrain._flat:
        grid = terrain._flat.get("cells") or cell_grid(terrain)
        terrain._flat["cells"] = grid

        def on(a: np.ndarray, dtype=x.dtype) -> Array:
            return xp.asarray(a, dtype=dtype, device=device_of(x))

        terrain._flat[key] = (
            _lookup(grid.xs, grid.x_bucket, grid.resolution, on, xp),
            _lookup(grid.ys, grid.y_bucket, grid.resolution, on, xp),
            on(grid.heights.ravel()),
            grid,
        )
    x_lookup, y_lookup, flat, grid = terrain._flat[key]
    shape = x.shape
    x, y = xp.reshape(x, (-1,)), xp.reshape(y, (-1,))
    i, j = _cell_index(x, x_lookup, xp), _cell_index(y, y_lookup, xp)
    h = xp.take(flat, j * (grid.xs.shape[0] + 1) + i)
    if grid.any_field:
        h = xp.where(xp.isnan(h), terrain.field_height_at(x, y), h)
    return xp.reshape(h, shape)
