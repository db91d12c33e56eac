"""Procedural terrain: a grid of square tiles (flat, stairs up/down, uneven blocks), with an
exact vectorised height query for each of its two representations in the physics.

Every built-in tile is piecewise constant on a rectilinear grid of its own (its `edges`: riser,
block and platform lines), so it is also stored as cells (`Tile.cells`) that the scene turns
into box geoms (`terrain.representation=boxes`); the 1 cm sample array `heights` is what the
heightfield representation compiles, and what previews draw.

Stairs are square pyramids around the tile centre. `stairs_up` is a pit: the robot spawns on
the bottom platform and climbs outwards in any direction; `stairs_down` is a hill it descends.
Stairs tiles' outer ring is at height 0, so they meet flat neighbours without a cliff;
uneven tiles run their blocks to the tile edge.
Risers are drawn once per tile (a real flight has equal risers), uniformly in the difficulty's
range; the tread is the difficulty's depth.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass, field

import numpy as np

from lca.arrays import Array, arrays, device_of, like, namespace
from lca.config.registry import TILES
from lca.sim.config import DifficultyConfig, TerrainConfig
from lca.sim.strips import Strips


@dataclass
class Tile:
    kind: str
    row: int
    col: int
    centre: tuple[float, float]  # world x, y
    params: dict[str, float] = field(default_factory=dict)
    # (edges, heights): local breakpoints from -tile_size/2 to +tile_size/2 (the same on x
    # and y) and the height of each cell between them, [y cell, x cell]; None for a tile
    # that is not piecewise constant (a plugin's slopes): it stays a heightfield
    cells: tuple[np.ndarray, np.ndarray] | None = field(default=None, compare=False)


@dataclass
class Terrain:
    """Heights on a regular grid: `heights[r, c]` is at x = x0 + c*res, y = y0 + r*res."""

    heights: np.ndarray
    resolution: float
    origin: tuple[float, float]
    tiles: list[Tile]
    # what the physics collides with: "heightfield" (the samples, triangulated) or "boxes"
    # (each tile's cells as boxes; tiles without cells stay a heightfield of their own)
    representation: str = "heightfield"
    tile_size: float = 0.0
    # a hardware task's ground as steps along one direction (rotated boxes): when set, the
    # physics and `height_at` use it, and `heights` only draws previews
    strips: Strips | None = None
    # render models only: the world box (lo, hi) outside which the boxes representation
    # leaves its boxes out (`lca.sim.render.window`); the physics always has all of them
    window: tuple[tuple[float, float], tuple[float, float]] | None = None
    _flat: dict = field(default_factory=dict, init=False, repr=False, compare=False)

    @property
    def size(self) -> tuple[float, float]:
        """World extent (x, y) in metres."""
        nrow, ncol = self.heights.shape
        return (ncol - 1) * self.resolution, (nrow - 1) * self.resolution

    @property
    def centre(self) -> tuple[float, float]:
        sx, sy = self.size
        return self.origin[0] + sx / 2, self.origin[1] + sy / 2

    def tile_centres(self) -> np.ndarray:
        return np.array([t.centre for t in self.tiles])

    def height_at(self, x: Array, y: Array) -> Array:
        """Surface height at world points, exactly as the physics sees it: the boxes' tops
        (a point on a vertical edge takes the cell on its +x / +y side), or the heightfield."""
        if self.strips is not None:
            return self.strips.height_at(x, y)
        if self.representation != "boxes":
            return self.field_height_at(x, y)
        from lca.sim.relief import cell_height_at

        return cell_height_at(self, x, y)

    def field_height_at(self, x: Array, y: Array) -> Array:
        """Surface height at world points, exactly as MuJoCo's heightfield triangulates it.

        Each grid cell is split along the diagonal from sample (r, c) to (r+1, c+1); points
        outside the grid are clamped to its edge. NumPy or torch points (numbers: NumPy).
        """
        x, y = arrays(x, y)
        xp = namespace(x, y)
        x, y = xp.broadcast_arrays(x, y)
        nrow, ncol = self.heights.shape
        u = xp.clip((x - self.origin[0]) / self.resolution, min=0, max=ncol - 1)
        v = xp.clip((y - self.origin[1]) / self.resolution, min=0, max=nrow - 1)
        c = xp.clip(xp.astype(u, xp.int64), max=ncol - 2)  # u >= 0, so truncation is floor
        r = xp.clip(xp.astype(v, xp.int64), max=nrow - 2)
        fx, fy = u - xp.astype(c, u.dtype), v - xp.astype(r, v.dtype)
        # flat gathers are much faster than 2-D fancy indexing on a large grid
        flat, i00 = self._flat_heights(u), r * ncol + c

        def at(index: Array) -> Array:
            return xp.reshape(xp.take(flat, xp.reshape(index, (-1,))), index.shape)

        h00, h01, h10, h11 = at(i00), at(i00 + 1), at(i00 + ncol), at(i00 + ncol + 1)
        lower = fx >= fy  # triangle (r,c), (r,c+1), (r+1,c+1)
        return xp.where(
            lower,
            h00 + fx * (h01 - h00) + fy * (h11 - h01),
            h00 + fy * (h10 - h00) + fx * (h11 - h10),
        )

    def _flat_heights(self, reference: Array) -> Array:
        """The grid, flattened, in `reference`'s array type, dtype and device (cached)."""
        key = (type(reference).__module__, str(device_of(reference)), str(reference.dtype))
        if key not in self._flat:
            self._flat[key] = like(self.heights.ravel(), reference)
        return self._flat[key]


def apportion(weights: list[float], n: int) -> np.ndarray:
    """`n` items split in proportion to `weights` by largest remainder (ties in order)."""
    w = np.asarray(weights, float)
    exact = w / w.sum() * n
    counts = np.floor(exact).astype(int)
    for i in np.argsort(-(exact - counts), kind="stable")[: n - counts.sum()]:
        counts[i] += 1
    return counts


def tile_kinds(cfg: TerrainConfig, rng: np.random.Generator, n: int | None = None) -> list[str]:
    """`n` tile types (default: the whole grid) in proportion to the mixture weights (largest
    remainder, ties in registration order), shuffled."""
    n = cfg.rows * cfg.cols if n is None else n
    names = TILES.names()
    counts = apportion([float(cfg.mixture.get(t, 0.0)) for t in names], n)
    kinds = [t for t, k in zip(names, counts, strict=True) for _ in range(k)]
    return [kinds[i] for i in rng.permutation(n)]


def _stairs(lx, ly, cfg, riser, tread, up: bool) -> np.ndarray:
    """Square pyramid of `num_steps` steps outside the central platform; outer ring at 0."""
    ring = np.maximum(np.abs(lx), np.abs(ly)) - cfg.platform / 2
    # Index of the step a point stands on: 0 on the platform, num_steps on the outer ring.
    # The small offset keeps points exactly on a step edge on the outer step.
    step = np.clip(np.floor(ring / tread + 1e-9) + 1, 0, cfg.num_steps)
    step = np.where(ring < 0, 0, step)
    levels_below_top = cfg.num_steps - step
    return -riser * levels_below_top if up else riser * levels_below_top


def stairs_edges(cfg: TerrainConfig, difficulty: DifficultyConfig) -> np.ndarray:
    """Local lines where a pyramid's height changes: the platform's and each riser's."""
    half = cfg.tile_size / 2
    rings = cfg.platform / 2 + difficulty.stairs_tread * np.arange(cfg.num_steps)
    rings = rings[rings < half - 1e-9]
    return np.unique(np.round(np.concatenate([[-half, half], rings, -rings]), 9))


def blocks_edges(cfg: TerrainConfig, difficulty: DifficultyConfig) -> np.ndarray:
    """Local lines where a block field's height changes: block sides and the platform's."""
    half = cfg.tile_size / 2
    nb = int(round(cfg.tile_size / cfg.block_size))
    sides = -half + cfg.block_size * np.arange(nb)
    platform = np.array([-cfg.platform / 2, cfg.platform / 2])
    return np.unique(np.round(np.concatenate([[half], sides, platform]), 9))


def _blocks(lx, ly, cfg, low, high, rng) -> np.ndarray:
    """Random block field; the spawn platform is one flat block."""
    half = cfg.tile_size / 2
    nb = int(round(cfg.tile_size / cfg.block_size))
    block_heights = rng.uniform(low, high, size=(nb, nb))
    # The epsilon keeps samples exactly on a block edge (k * block_size) in block k.
    bi = np.clip(np.floor((ly + half) / cfg.block_size + 1e-9).astype(int), 0, nb - 1)
    bj = np.clip(np.floor((lx + half) / cfg.block_size + 1e-9).astype(int), 0, nb - 1)
    h = block_heights[bi, bj]
    on_platform = np.maximum(np.abs(lx), np.abs(ly)) <= cfg.platform / 2
    return np.where(on_platform, (low + high) / 2, h)


# Tile generators: (lx, ly) are sample offsets (m) from the tile centre; each returns the
# heights there and the parameters it drew. They run in tile order on one RNG stream.
TileOut = tuple[np.ndarray, dict[str, float]]


def flat_edges(cfg: TerrainConfig, difficulty: DifficultyConfig) -> np.ndarray:
    return np.array([-cfg.tile_size / 2, cfg.tile_size / 2])


# A tile registers `edges=f(cfg, difficulty)` when its height is constant between those
# local lines (on x and on y): it can then be built from boxes.
@TILES.register("flat", label="Flat", edges=flat_edges)
def flat_tile(lx, ly, cfg: TerrainConfig, difficulty: DifficultyConfig, rng) -> TileOut:
    return np.zeros_like(lx), {}


def _stairs_tile(lx, ly, cfg, difficulty, rng, up: bool) -> TileOut:
    riser = float(rng.uniform(*difficulty.stairs_riser))
    params = {"riser": riser, "tread": difficulty.stairs_tread}
    return _stairs(lx, ly, cfg, riser, difficulty.stairs_tread, up=up), params


@TILES.register("stairs_up", label="Stairs up", edges=stairs_edges)
def stairs_up_tile(lx, ly, cfg: TerrainConfig, difficulty: DifficultyConfig, rng) -> TileOut:
    return _stairs_tile(lx, ly, cfg, difficulty, rng, up=True)


@TILES.register("stairs_down", label="Stairs down", edges=stairs_edges)
def stairs_down_tile(lx, ly, cfg: TerrainConfig, difficulty: DifficultyConfig, rng) -> TileOut:
    return _stairs_tile(lx, ly, cfg, difficulty, rng, up=False)


@TILES.register("uneven", label="Uneven Terrain", edges=blocks_edges)
def uneven_tile(lx, ly, cfg: TerrainConfig, difficulty: DifficultyConfig, rng) -> TileOut:
    low, high = difficulty.uneven_height
    return _blocks(lx, ly, cfg, low, high, rng), {"low": low, "high": high}


def level_difficulty(
    difficulty: DifficultyConfig, level: int, levels: int, start: float | None = None
) -> DifficultyConfig:
    """Row `level` of a levelled grid: riser and block heights at a fraction of the
    difficulty's rising evenly from `start` on row 0 (None: 1 / levels) to 1 on the last
    row, so the last row is the difficulty itself (treads stay)."""
    start = 1 / levels if start is None else start
    scale = 1.0 if levels == 1 else start + (1 - start) * level / (levels - 1)
    out = copy.deepcopy(difficulty)
    out.stairs_riser = [scale * h for h in difficulty.stairs_riser]
    out.uneven_height = [scale * h for h in difficulty.uneven_height]
    return out


def grid_kinds(cfg: TerrainConfig, rng: np.random.Generator) -> list[str]:
    """Row-major tile types; a levelled grid has one type per column, the same on every row."""
    if not cfg.levels:
        return tile_kinds(cfg, rng)
    return tile_kinds(cfg, rng, cfg.cols) * cfg.rows


def generate(cfg: TerrainConfig, difficulty: DifficultyConfig, seed: int | None = None) -> Terrain:
    """Build the whole tile grid. Deterministic in (config, difficulty, seed). With
    `cfg.levels` the rows are difficulty levels (`level_difficulty`), easiest first."""
    rng = np.random.default_rng(cfg.seed if seed is None else seed)
    res = cfg.resolution
    tile_n = int(round(cfg.tile_size / res))
    border_n = int(round(cfg.border / res))
    nrow = cfg.rows * tile_n + 2 * border_n + 1
    ncol = cfg.cols * tile_n + 2 * border_n + 1
    heights = np.zeros((nrow, ncol))
    origin = (-cfg.border, -cfg.border)
    local = (np.arange(tile_n) - tile_n / 2) * res  # sample offsets from a tile centre
    ly, lx = np.meshgrid(local, local, indexing="ij")
    tiles = []
    for index, kind in enumerate(grid_kinds(cfg, rng)):
        row, col = divmod(index, cfg.cols)
        centre = ((col + 0.5) * cfg.tile_size, (row + 0.5) * cfg.tile_size)
        level = (
            level_difficulty(difficulty, row, cfg.rows, cfg.levels_from)
            if cfg.levels
            else difficulty
        )
        h, params, cells = _tile(kind, lx, ly, cfg, level, rng)
        r0, c0 = border_n + row * tile_n, border_n + col * tile_n
        heights[r0 : r0 + tile_n, c0 : c0 + tile_n] = h
        tiles.append(Tile(kind, row, col, centre, params, cells))
    return Terrain(heights, res, origin, tiles, cfg.representation, cfg.tile_size)


def _tile(kind, lx, ly, cfg, difficulty, rng) -> tuple[np.ndarray, dict, tuple | None]:
    """A tile's samples, drawn parameters and cells. The cell heights come from the same call
    (its cell centres appended to the sample points), so they share its random draws."""
    edges_of = TILES.entry(kind).meta.get("edges")
    if edges_of is None:
        h, params = TILES[kind](lx, ly, cfg, difficulty, rng)
        return h, params, None
    edges = edges_of(cfg, difficulty)
    mid = (edges[:-1] + edges[1:]) / 2
    cy, cx = np.meshgrid(mid, mid, indexing="ij")
    points_x = np.concatenate([lx.ravel(), cx.ravel()])
    points_y = np.concatenate([ly.ravel(), cy.ravel()])
    h, params = TILES[kind](points_x, points_y, cfg, difficulty, rng)
    return h[: lx.size].reshape(lx.shape), params, (edges, h[lx.size :].reshape(cx.shape))
