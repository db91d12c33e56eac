"""Procedural terrain measured from the generated heightfield itself."""

from __future__ import annotations

from collections import Counter

import numpy as np
import pytest

from lca.config import compose
from lca.config.registry import TILES
from lca.sim.terrain import Terrain, Tile, generate, tile_kinds

# Paper table "Environment parameters" (m).
PAPER = {
    "medium": {"riser": (0.14, 0.18), "tread": 0.31, "uneven": (0.05, 0.20)},
    "hard": {"riser": (0.16, 0.20), "tread": 0.23, "uneven": (0.05, 0.40)},
}
# Two layouts: the smoke grid (2x2 tiles of 4 m, 4 steps) and full-size 8 m tiles (8 steps).
LAYOUTS = {
    "smoke": ["scale=smoke"],
    "full": ["terrain.rows=1", "terrain.cols=2"],
}


def centre_sample(terrain: Terrain, tile: Tile) -> tuple[int, int]:
    """(row, col) index of the heightfield sample at a tile centre."""
    res = terrain.resolution
    r = int(round((tile.centre[1] - terrain.origin[1]) / res))
    c = int(round((tile.centre[0] - terrain.origin[0]) / res))
    assert abs(terrain.origin[0] + c * res - tile.centre[0]) < 1e-9
    assert abs(terrain.origin[1] + r * res - tile.centre[1]) < 1e-9
    return r, c


def tile_region(terrain: Terrain, tile: Tile, tile_size: float) -> np.ndarray:
    """The heights a tile owns: samples at offsets [-tile_size/2, tile_size/2) from its centre."""
    half = int(round(tile_size / 2 / terrain.resolution))
    r, c = centre_sample(terrain, tile)
    return terrain.heights[r - half : r + half, c - half : c + half]


def profiles(terrain: Terrain, tile: Tile, tile_size: float) -> dict[str, np.ndarray]:
    """Heights from the tile centre outwards to its edge, along +x, -x, +y and -y."""
    half = int(round(tile_size / 2 / terrain.resolution))
    r, c = centre_sample(terrain, tile)
    h = terrain.heights
    return {
        "+x": h[r, c : c + half],
        "-x": h[r, c - half : c + 1][::-1],
        "+y": h[r : r + half, c],
        "-y": h[r - half : r + 1, c][::-1],
    }


@pytest.mark.parametrize("layout", sorted(LAYOUTS))
@pytest.mark.parametrize("difficulty", ["medium", "hard"])
@pytest.mark.parametrize("kind", ["stairs_up", "stairs_down"])
def test_stairs_match_difficulty(kind: str, difficulty: str, layout: str) -> None:
    cfg = compose([f"terrain={kind}", f"difficulty={difficulty}", *LAYOUTS[layout]])
    terrain = generate(cfg.terrain, cfg.difficulty)
    res, tc = terrain.resolution, cfg.terrain
    lo, hi = PAPER[difficulty]["riser"]
    tread = PAPER[difficulty]["tread"]
    assert len(terrain.tiles) == tc.rows * tc.cols
    for tile in terrain.tiles:
        assert tile.kind == kind
        for direction, prof in profiles(terrain, tile, tc.tile_size).items():
            where = f"tile ({tile.row}, {tile.col}) {direction}"
            diffs = np.diff(prof)
            jumps = np.flatnonzero(np.abs(diffs) > 1e-9)
            assert len(jumps) == tc.num_steps, where
            risers = diffs[jumps]
            # stairs_up is a pit (heights rise outwards), stairs_down a hill (they fall).
            assert np.all(risers > 0) if kind == "stairs_up" else np.all(risers < 0), where
            riser = np.abs(risers)
            assert np.ptp(riser) < 1e-9, f"{where}: unequal risers {riser}"
            assert lo - 1e-9 <= riser[0] <= hi + 1e-9, f"{where}: riser {riser[0]}"
            assert abs(riser[0] - tile.params["riser"]) < 1e-9, where
            # Distance from the centre of the first sample on each new step = the step edges.
            edges = (jumps + 1) * res
            assert abs(edges[0] - tc.platform / 2) < 1e-6, f"{where}: platform edge {edges[0]}"
            treads = np.diff(edges)
            assert np.all(np.abs(treads - tread) < 1e-6), f"{where}: treads {treads}"
            # Flat platform at the centre, outer ring at 0.
            sign = -1.0 if kind == "stairs_up" else 1.0
            assert abs(prof[0] - sign * tc.num_steps * riser[0]) < 1e-9, where
            assert prof[-1] == 0.0, where


@pytest.mark.parametrize("difficulty", ["medium", "hard"])
def test_uneven_blocks_within_difficulty_range(difficulty: str) -> None:
    cfg = compose(["terrain=uneven", f"difficulty={difficulty}", "scale=smoke"])
    terrain = generate(cfg.terrain, cfg.difficulty)
    lo, hi = PAPER[difficulty]["uneven"]
    for tile in terrain.tiles:
        assert tile.kind == "uneven"
        assert (tile.params["low"], tile.params["high"]) == pytest.approx((lo, hi))
        region = tile_region(terrain, tile, cfg.terrain.tile_size)
        assert region.min() >= lo and region.max() <= hi, (region.min(), region.max())
        # A real random field: many distinct block heights spread over the range.
        assert len(np.unique(region)) > 50
        assert region.min() < lo + 0.25 * (hi - lo) and region.max() > hi - 0.25 * (hi - lo)
        # The spawn platform is one flat block at mid height.
        r, c = centre_sample(terrain, tile)
        assert terrain.heights[r, c] == pytest.approx((lo + hi) / 2)


def test_uneven_block_edges_on_block_grid() -> None:
    cfg = compose(["terrain=uneven", "scale=smoke"])
    terrain = generate(cfg.terrain, cfg.difficulty)
    block_n = int(round(cfg.terrain.block_size / terrain.resolution))
    for tile in terrain.tiles:
        region = tile_region(terrain, tile, cfg.terrain.tile_size)
        # First row and column of blocks: away from the central spawn platform.
        for line in (region[block_n // 2], region[:, block_n // 2]):
            edges = np.flatnonzero(np.diff(line) != 0) + 1
            assert np.all(edges % block_n == 0), f"block edges at samples {edges}"


def test_field_height_at_exact_on_samples_and_triangles(mixed_cfg) -> None:
    """The heightfield representation's query (test_relief.py checks the boxes')."""
    terrain = generate(mixed_cfg.terrain, mixed_cfg.difficulty)
    h, res = terrain.heights, terrain.resolution
    (ox, oy), (nrow, ncol) = terrain.origin, h.shape
    rng = np.random.default_rng(1)
    r = rng.integers(0, nrow, 500)
    c = rng.integers(0, ncol, 500)
    # Include the last row/column and the corners.
    r = np.r_[r, 0, nrow - 1, 0, nrow - 1]
    c = np.r_[c, 0, 0, ncol - 1, ncol - 1]
    np.testing.assert_allclose(
        terrain.field_height_at(ox + c * res, oy + r * res), h[r, c], atol=1e-12
    )
    # Inside a cell: the diagonal runs from (r, c) to (r+1, c+1), so the cell centre is the
    # mean of those two samples, and a point on a row edge interpolates that edge. Random
    # cells, plus every cell whose corners are not coplanar (where the diagonal matters).
    bent = np.argwhere(np.abs(h[:-1, :-1] + h[1:, 1:] - h[:-1, 1:] - h[1:, :-1]) > 1e-3)
    assert len(bent) > 50
    r = np.r_[rng.integers(0, nrow - 1, 500), bent[:, 0]]
    c = np.r_[rng.integers(0, ncol - 1, 500), bent[:, 1]]
    x, y = ox + (c + 0.5) * res, oy + (r + 0.5) * res
    np.testing.assert_allclose(
        terrain.field_height_at(x, y), (h[r, c] + h[r + 1, c + 1]) / 2, atol=1e-12
    )
    f = rng.uniform(0, 1, len(r))
    np.testing.assert_allclose(
        terrain.field_height_at(ox + (c + f) * res, oy + r * res),
        (1 - f) * h[r, c] + f * h[r, c + 1],
        atol=1e-12,
    )


def test_same_seed_same_terrain(mixed_cfg) -> None:
    a = generate(mixed_cfg.terrain, mixed_cfg.difficulty, seed=7)
    b = generate(mixed_cfg.terrain, mixed_cfg.difficulty, seed=7)
    assert np.array_equal(a.heights, b.heights)
    assert a.tiles == b.tiles
    c = generate(mixed_cfg.terrain, mixed_cfg.difficulty, seed=8)
    assert not np.array_equal(a.heights, c.heights)
    # terrain.seed in the config is the default seed.
    cfg7 = compose(["terrain=mixed", "scale=smoke", "terrain.seed=7"])
    assert np.array_equal(generate(cfg7.terrain, cfg7.difficulty).heights, a.heights)


def test_mixture_gives_each_kind_equally() -> None:
    cfg = compose(["terrain=mixed", "terrain.rows=4", "terrain.cols=4"])
    for seed in range(5):
        counts = Counter(tile_kinds(cfg.terrain, np.random.default_rng(seed)))
        assert counts == dict.fromkeys(TILES.names(), 4), counts
    terrain = generate(cfg.terrain, cfg.difficulty)
    assert Counter(t.kind for t in terrain.tiles) == dict.fromkeys(TILES.names(), 4)
    # Each tile's heights match its kind.
    lo, hi = cfg.difficulty.uneven_height
    for tile in terrain.tiles:
        region = tile_region(terrain, tile, cfg.terrain.tile_size)
        r, c = centre_sample(terrain, tile)
        centre = terrain.heights[r, c]
        if tile.kind == "flat":
            assert np.all(region == 0.0)
        elif tile.kind == "stairs_up":
            assert centre == pytest.approx(-cfg.terrain.num_steps * tile.params["riser"])
        elif tile.kind == "stairs_down":
            assert centre == pytest.approx(cfg.terrain.num_steps * tile.params["riser"])
        else:
            assert centre == pytest.approx((lo + hi) / 2)
            assert region.min() >= lo and region.max() <= hi
