"""The boxes representation is the same terrain as the heightfield: the drawn dimensions read
back from the compiled model, the height query against plain MuJoCo's ray casts, and the
actor's and critic's maps for the same state."""

from __future__ import annotations

import dataclasses
import functools

import mujoco
import numpy as np
import pytest

from lca.config import compose
from lca.sim.relief import cell_grid, rectangles
from lca.sim.scene import build_scene
from lca.sim.terrain import generate
from lca.task.heightmap import grid_offsets, sample_heights

# Paper table "Environment parameters" (m).
PAPER = {
    "medium": {"riser": (0.14, 0.18), "tread": 0.31, "uneven": (0.05, 0.20)},
    "hard": {"riser": (0.16, 0.20), "tread": 0.23, "uneven": (0.05, 0.40)},
}
KINDS = ("flat", "stairs_up", "stairs_down", "uneven")
# full-size 8 m tiles, one of each kind
FULL = ["terrain=mixed", "terrain.rows=2", "terrain.cols=2", "terrain.apron=2"]


@functools.cache
def scene_of(difficulty: str, representation: str = "boxes"):
    cfg = compose([*FULL, f"difficulty={difficulty}", f"terrain.representation={representation}"])
    return build_scene(cfg)


def box_geoms(model: mujoco.MjModel, tile) -> list[tuple[np.ndarray, np.ndarray]]:
    """(low corner, high corner) of each terrain box inside `tile`, in the tile's frame."""
    out = []
    for g in range(model.ngeom):
        name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_GEOM, g) or ""
        if not name.startswith("terrain_box"):
            continue
        pos, size = model.geom_pos[g], model.geom_size[g]
        centre = np.array([*tile.centre, 0.0])
        if np.all(np.abs(pos[:2] - centre[:2]) < 4.0):
            out.append((pos - size - centre, pos + size - centre))
    return out


def ray_heights(scene, x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, list[str]]:
    """Heights where rays cast straight down from 5 m above hit, and the geoms they hit."""
    model = scene.model
    data = mujoco.MjData(model)
    data.qpos[:] = scene.home_qpos
    data.qpos[2] = 100.0  # lift the robot out of the way of the rays
    mujoco.mj_forward(model, data)
    geomid = np.zeros(1, np.int32)
    down = np.array([0.0, 0.0, -1.0])
    dist, hit_ids = np.empty(len(x)), np.empty(len(x), int)
    for i, (xi, yi) in enumerate(zip(x, y, strict=True)):
        dist[i] = mujoco.mj_ray(model, data, np.array([xi, yi, 5.0]), down, None, 1, -1, geomid)
        hit_ids[i] = geomid[0]
    names = [mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_GEOM, g) or "" for g in hit_ids]
    return 5.0 - dist, names


def edge_points(scene, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """Uniform points over the tiles, plus points 1 mm either side of every box edge."""
    terrain = scene.terrain
    size = terrain.tile_size * 2
    x, y = list(rng.uniform(-1, size + 1, 4000)), list(rng.uniform(-1, size + 1, 4000))
    for tile in terrain.tiles:
        edges = tile.cells[0]
        for e in edges:
            for side in (-1e-3, 1e-3):
                along = rng.uniform(-terrain.tile_size / 2, terrain.tile_size / 2, 20)
                x += [tile.centre[0] + e + side] * len(along)
                y += list(tile.centre[1] + along)
                x += list(tile.centre[0] + along)
                y += [tile.centre[1] + e + side] * len(along)
    return np.array(x), np.array(y)


@pytest.mark.parametrize("difficulty", ["medium", "hard"])
def test_height_at_matches_raycast_of_boxes(difficulty: str) -> None:
    scene = scene_of(difficulty)
    x, y = edge_points(scene, np.random.default_rng(0))
    hit, names = ray_heights(scene, x, y)
    assert all(n.startswith(("terrain_box", "apron")) for n in names), set(names)
    assert len(x) > 5000
    np.testing.assert_allclose(hit, scene.terrain.height_at(x, y), rtol=0, atol=1e-6)


@pytest.mark.parametrize("difficulty", ["medium", "hard"])
def test_compiled_stairs_and_blocks_have_the_paper_dimensions(difficulty: str) -> None:
    scene, paper = scene_of(difficulty), PAPER[difficulty]
    cfg = compose([*FULL, f"difficulty={difficulty}"])
    seen = set()
    for tile in scene.terrain.tiles:
        boxes = box_geoms(scene.model, tile)
        tops = np.unique(np.round([hi[2] for _, hi in boxes], 9))
        seen.add(tile.kind)
        if tile.kind == "flat":
            assert len(boxes) == 1 and tops.tolist() == [0.0]
        elif tile.kind.startswith("stairs"):
            # num_steps + 1 levels, equal risers within the paper's range
            assert len(tops) == cfg.terrain.num_steps + 1
            risers = np.diff(tops)
            np.testing.assert_allclose(risers, risers[0], atol=1e-9)
            assert paper["riser"][0] <= risers[0] <= paper["riser"][1]
            # tread: the ring width between consecutive box faces outside the platform
            faces = np.unique(np.round([hi[0] for _, hi in boxes], 9))
            rings = faces[(faces > cfg.terrain.platform / 2 - 1e-9) & (faces < 4 - 1e-9)]
            np.testing.assert_allclose(np.diff(rings), paper["tread"], atol=1e-9)
            assert len(rings) == cfg.terrain.num_steps
            assert len(boxes) <= 4 * cfg.terrain.num_steps + 1  # rings of four, one platform
        else:
            low, high = paper["uneven"]
            assert np.all((tops >= low - 1e-9) & (tops <= high + 1e-9))
            block = cfg.terrain.block_size
            widths = np.array([hi[:2] - lo[:2] for lo, hi in boxes])
            whole = np.abs(widths - block) < 1e-9
            assert whole.all(axis=1).mean() > 0.9  # all but the platform's neighbours
            assert len(tops) > 300  # drawn per block
    assert seen == set(KINDS)


def test_same_draws_in_both_representations() -> None:
    boxes, field = scene_of("hard"), scene_of("hard", "heightfield")
    np.testing.assert_array_equal(boxes.terrain.heights, field.terrain.heights)
    for a, b in zip(boxes.terrain.tiles, field.terrain.tiles, strict=True):
        assert (a.kind, a.params) == (b.kind, b.params)
    assert field.model.geom("terrain").type[0] == mujoco.mjtGeom.mjGEOM_HFIELD


@pytest.mark.parametrize("difficulty", ["medium", "hard"])
def test_maps_agree_between_representations(difficulty: str) -> None:
    """Actor (11 x 11 over 1 m) and critic (16 x 16 over 1.5 m) maps for the same states are
    equal wherever a map point is more than one heightfield sample (1 cm) from an edge: there
    the heightfield's riser is a 1 cm ramp, the boxes' vertical."""
    cfg = compose([*FULL, f"difficulty={difficulty}"])
    terrain = generate(cfg.terrain, cfg.difficulty)
    field = dataclasses.replace(terrain, representation="heightfield")
    rng = np.random.default_rng(1)
    n = 512
    xy = rng.uniform(0.5, 2 * cfg.terrain.tile_size - 0.5, (n, 2))
    yaw = rng.uniform(-np.pi, np.pi, n)
    for shape, spacing in (((11, 11), 0.1), ((16, 16), 0.1)):
        offsets = grid_offsets(shape, spacing)
        a = sample_heights(terrain, xy, yaw, offsets)
        b = sample_heights(field, xy, yaw, offsets)
        near = _near_edge(terrain, xy, yaw, offsets, terrain.resolution)
        np.testing.assert_array_equal(a[~near], b[~near])
        assert near.mean() < 0.15
        assert np.all(np.abs(a - b)[near] <= PAPER[difficulty]["uneven"][1] + 1e-9)


def _near_edge(terrain, xy, yaw, offsets, within: float) -> np.ndarray:
    cos, sin = np.cos(yaw)[:, None], np.sin(yaw)[:, None]
    x = xy[:, :1] + cos * offsets[None, :, 0] - sin * offsets[None, :, 1]
    y = xy[:, 1:] + sin * offsets[None, :, 0] + cos * offsets[None, :, 1]
    near = np.zeros(x.shape, bool)
    for tile in terrain.tiles:
        lines = tile.cells[0]
        for coord, centre in ((x, tile.centre[0]), (y, tile.centre[1])):
            d = np.min(np.abs((coord - centre)[..., None] - lines), axis=-1)
            near |= d <= within + 1e-9
    return near


def test_rectangles_cover_cells_once() -> None:
    rng = np.random.default_rng(0)
    cells = rng.integers(0, 3, (9, 7)).astype(float)
    cover = np.zeros(cells.shape, int)
    for r0, r1, c0, c1 in rectangles(cells):
        assert np.all(cells[r0:r1, c0:c1] == cells[r0, c0])
        cover[r0:r1, c0:c1] += 1
    assert np.all(cover == 1)
    rings = np.maximum(*np.abs(np.mgrid[-4:5, -4:5]))  # concentric squares: 4 per ring + 1
    assert len(rectangles(rings.astype(float))) == 4 * 4 + 1


def test_height_at_on_torch_matches_numpy() -> None:
    torch = pytest.importorskip("torch")
    terrain = scene_of("medium").terrain
    rng = np.random.default_rng(2)
    x, y = rng.uniform(-2, 18, 1000), rng.uniform(-2, 18, 1000)
    on_torch = terrain.height_at(torch.as_tensor(x), torch.as_tensor(y))
    np.testing.assert_array_equal(on_torch.numpy(), terrain.height_at(x, y))


def test_cell_lookup_is_exact_at_every_line() -> None:
    """The bucket lookup finds the cell a binary search finds, on every line and on the
    floats either side of it (where rounding decides), and far outside the grid."""
    cfg = compose([*FULL, "difficulty=hard"])
    terrain = generate(cfg.terrain, cfg.difficulty)
    grid = cell_grid(terrain)
    rng = np.random.default_rng(3)
    lines = np.concatenate([grid.xs, grid.ys])
    near = np.concatenate([lines, np.nextafter(lines, -np.inf), np.nextafter(lines, np.inf)])
    across = rng.uniform(-50, 50, len(near))
    x = np.concatenate([near, across, rng.uniform(-50, 50, 5000)])
    y = np.concatenate([across, near, rng.uniform(-50, 50, 5000)])
    i = np.searchsorted(grid.xs, x, side="right")
    j = np.searchsorted(grid.ys, y, side="right")
    np.testing.assert_array_equal(terrain.height_at(x, y), grid.heights[j, i])
