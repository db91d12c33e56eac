"""The deployment perception filter (paper, "Perception Filtering") stage by stage, on
hand-made point clouds: min-height downsampling into the robot-centred, yaw-aligned 11 x 11
grid, outlier clamp, zero-mean + clip, 5 cm quantisation, and the whole `deployment_map`."""

from __future__ import annotations

import numpy as np
import pytest

from lca.task import heightmap, perception

SHAPE = (11, 11)
SPACING = 0.1
GAMMA = 2.0  # conf/perception/deployment.yaml
QUANTUM = 0.05
CELLS = SHAPE[0] * SHAPE[1]
# Sub-cell offsets well inside a 10 cm cell.
SUB = np.array([-0.035, -0.015, 0.0, 0.015, 0.035])


def cell(row: int, col: int) -> int:
    return row * SHAPE[1] + col


def to_world(ahead, left, z, base_xy, yaw) -> np.ndarray:
    """(P, 3) world points from robot-frame (ahead, left) coordinates."""
    ahead, left, z = np.broadcast_arrays(*(np.asarray(v, float) for v in (ahead, left, z)))
    c, s = np.cos(yaw), np.sin(yaw)
    x = base_xy[0] + c * ahead - s * left
    y = base_xy[1] + s * ahead + c * left
    return np.stack([x.ravel(), y.ravel(), z.ravel()], axis=1)


def cell_cloud(height_of_row_col, base_xy, yaw, rng=None, noise=0.0) -> np.ndarray:
    """25 points in every cell, heights from `height_of_row_col(row, col)` (+ noise)."""
    pts = []
    for r in range(SHAPE[0]):
        for c in range(SHAPE[1]):
            a = (SHAPE[0] - 1) / 2 * SPACING - r * SPACING + SUB[:, None]
            left = (SHAPE[1] - 1) / 2 * SPACING - c * SPACING + SUB[None, :]
            z = np.full((SUB.size, SUB.size), float(height_of_row_col(r, c)))
            if noise:
                z = z + rng.uniform(-noise, noise, z.shape)
            pts.append(to_world(a, left, z, base_xy, yaw))
    return np.concatenate(pts)


def grid_of(points: np.ndarray, base_xy, yaw, valid=None):
    valid = np.ones(len(points), bool) if valid is None else valid
    return perception.min_height_grid(
        points[None], valid[None], np.asarray(base_xy, float)[None], np.array([yaw]), SHAPE, SPACING
    )


# ---- downsampling -----------------------------------------------------------------------


@pytest.mark.parametrize("yaw", [0.0, 0.7, np.pi / 2, -2.5])
def test_heightmap_grid_points_fall_in_their_own_cells(yaw):
    """The filter's cells are the task layer's grid: row 0 farthest ahead, column 0 left."""
    base = np.array([3.2, -1.4])
    offsets = heightmap.grid_offsets(SHAPE, SPACING)
    pts = to_world(offsets[:, 0], offsets[:, 1], 0.0, base, yaw)
    index, inside = perception.cell_indices(pts[None], base[None], np.array([yaw]), SHAPE, SPACING)
    assert inside.all()
    np.testing.assert_array_equal(index[0], np.arange(CELLS))


def test_row_zero_is_ahead_and_column_zero_is_left():
    base, yaw = np.zeros(2), 0.0
    pts = to_world([0.5, -0.5, 0.0, 0.0, 0.3], [0.0, 0.0, 0.5, -0.5, 0.0], 0.0, base, yaw)
    index, inside = perception.cell_indices(pts[None], base[None], np.array([yaw]), SHAPE, SPACING)
    assert inside.all()
    assert index[0].tolist() == [cell(0, 5), cell(10, 5), cell(5, 0), cell(5, 10), cell(2, 5)]


def test_yaw_alignment_at_quarter_turn():
    """Facing +y: 0.3 m ahead is world +y; world +x is on the robot's right."""
    base, yaw = np.array([1.0, 2.0]), np.pi / 2
    ahead_pt = np.array([[1.0, 2.3, 0.7]])
    right_pt = np.array([[1.3, 2.0, 0.4]])
    grid, filled = grid_of(np.concatenate([ahead_pt, right_pt]), base, yaw)
    assert np.flatnonzero(filled[0]).tolist() == [cell(2, 5), cell(5, 8)]
    assert grid[0, cell(2, 5)] == pytest.approx(0.7)
    assert grid[0, cell(5, 8)] == pytest.approx(0.4)
    # The same world points seen while facing +x land elsewhere.
    _, filled_x = grid_of(np.concatenate([ahead_pt, right_pt]), base, 0.0)
    assert np.flatnonzero(filled_x[0]).tolist() == sorted([cell(5, 2), cell(2, 5)])


def test_points_outside_the_grid_are_ignored():
    base, yaw = np.array([0.5, 0.5]), 0.3
    floor = cell_cloud(lambda r, c: 0.2, base, yaw)
    # Very low points just beyond the outer cells' edges (0.55 m) and far away.
    outside = to_world(
        [0.56, -0.56, 0.0, 0.0, 0.6, 2.0, -3.0],
        [0.0, 0.0, 0.56, -0.56, 0.6, 0.0, 1.0],
        -5.0,
        base,
        yaw,
    )
    index, inside = perception.cell_indices(
        outside[None], base[None], np.array([yaw]), SHAPE, SPACING
    )
    assert not inside.any()
    with_junk, filled = grid_of(np.concatenate([floor, outside]), base, yaw)
    clean, _ = grid_of(floor, base, yaw)
    np.testing.assert_array_equal(with_junk, clean)
    assert filled.all() and np.allclose(clean, 0.2)
    # ...while a low point just inside an outer cell does lower it.
    edge = to_world([0.54], [0.0], -5.0, base, yaw)
    lowered, _ = grid_of(np.concatenate([floor, edge]), base, yaw)
    assert lowered[0, cell(0, 5)] == -5.0
    assert np.count_nonzero(lowered != clean) == 1


def test_invalid_points_are_ignored():
    base, yaw = np.zeros(2), 0.0
    floor = cell_cloud(lambda r, c: 0.1, base, yaw)
    junk = to_world([0.0, 0.2], [0.0, -0.1], [-3.0, -7.0], base, yaw)
    valid = np.r_[np.ones(len(floor), bool), np.zeros(len(junk), bool)]
    grid, filled = grid_of(np.concatenate([floor, junk]), base, yaw, valid)
    assert filled.all()
    np.testing.assert_allclose(grid, 0.1)


def test_min_height_occluded_stair_cell_takes_the_lower_step():
    """A cell straddling a stair edge: mostly upper-step points, a few of the lower step
    (the rest hidden behind the riser) -> the lower step's height, not an average."""
    base, yaw = np.zeros(2), 0.0
    rng = np.random.default_rng(0)
    upper = to_world(rng.uniform(0.15, 0.25, 40), rng.uniform(-0.05, 0.05, 40), 0.18, base, yaw)
    lower = to_world([0.16, 0.17, 0.16], [0.01, -0.02, 0.03], 0.0, base, yaw)
    only_upper = to_world(
        rng.uniform(0.25, 0.35, 30), rng.uniform(-0.05, 0.05, 30), 0.18, base, yaw
    )
    grid, filled = grid_of(np.concatenate([upper, lower, only_upper]), base, yaw)
    assert np.flatnonzero(filled[0]).tolist() == [cell(2, 5), cell(3, 5)]
    assert grid[0, cell(3, 5)] == 0.0  # the occluded lower step wins
    assert grid[0, cell(2, 5)] == pytest.approx(0.18)


def test_min_height_is_per_environment():
    bases = np.array([[0.0, 0.0], [10.0, -4.0]])
    yaws = np.array([0.0, np.pi])
    a = cell_cloud(lambda r, c: 0.3, bases[0], yaws[0])
    b = cell_cloud(lambda r, c: 0.3 + 0.01 * r, bases[1], yaws[1])
    pts, valid = np.stack([a, b]), np.ones((2, len(a)), bool)
    grid, filled = perception.min_height_grid(pts, valid, bases, yaws, SHAPE, SPACING)
    assert filled.all()
    np.testing.assert_allclose(grid[0], 0.3)
    expected = np.broadcast_to(0.3 + 0.01 * np.arange(11)[:, None], SHAPE)
    np.testing.assert_allclose(grid[1].reshape(SHAPE), expected)


# ---- outlier rejection ------------------------------------------------------------------


def test_empty_cells_are_set_to_the_mean_of_the_filled_ones():
    base, yaw = np.zeros(2), 0.0
    pts = to_world([0.0, 0.3, -0.2], [0.0, 0.1, -0.4], [0.1, 0.2, 0.3], base, yaw)
    grid, filled = grid_of(pts, base, yaw)
    assert filled.sum() == 3 and np.isinf(grid[~filled]).all()
    out, mu = perception.reject_outliers(grid, filled, GAMMA)
    assert mu[0, 0] == pytest.approx(0.2)
    np.testing.assert_allclose(out[0, ~filled[0]], 0.2)
    np.testing.assert_allclose(out[filled], grid[filled])  # within gamma sigma: kept


def test_single_spike_cell_is_clamped_to_the_mean():
    grid = np.zeros((1, CELLS))
    grid[0, cell(4, 6)] = 0.5  # e.g. the robot's own knee
    filled = np.ones_like(grid, bool)
    mu, sigma = grid.mean(), grid.std()
    assert abs(0.5 - mu) >= GAMMA * sigma and abs(0.0 - mu) < GAMMA * sigma
    out, mu_out = perception.reject_outliers(grid, filled, GAMMA)
    assert mu_out[0, 0] == pytest.approx(mu)
    assert out[0, cell(4, 6)] == pytest.approx(mu)
    others = np.delete(out[0], cell(4, 6))
    assert (others == 0.0).all()


def test_outlier_threshold_is_inclusive():
    """|g - mu| >= gamma sigma: on the boundary a cell is an outlier."""
    grid, filled = np.array([[-1.0, 1.0]]), np.ones((1, 2), bool)  # mu 0, sigma 1 exactly
    out, mu = perception.reject_outliers(grid, filled, 1.0)
    assert mu[0, 0] == 0.0
    np.testing.assert_array_equal(out, [[0.0, 0.0]])
    out, _ = perception.reject_outliers(grid, filled, 1.0 + 1e-9)
    np.testing.assert_array_equal(out, grid)


def test_gentle_terrain_has_no_outliers():
    grid = np.where(np.arange(CELLS) % 2 == 0, 0.3, 0.5)[None]  # a checkerboard of blocks
    out, mu = perception.reject_outliers(grid, np.ones_like(grid, bool), GAMMA)
    np.testing.assert_array_equal(out, grid)
    assert mu[0, 0] == pytest.approx(grid.mean())


@pytest.mark.parametrize("height", [0.0, 0.37, -1.3])
def test_perfectly_flat_grid_has_no_outliers(height):
    grid = np.full((2, CELLS), height)
    out, mu = perception.reject_outliers(grid, np.ones_like(grid, bool), GAMMA)
    np.testing.assert_allclose(out, height, rtol=0, atol=1e-12)
    np.testing.assert_allclose(mu, height, rtol=0, atol=1e-12)


# ---- zero-mean, clip, quantise ----------------------------------------------------------


def test_map_is_zero_mean_without_quantisation():
    base, yaw = np.array([-2.0, 1.0]), 1.1
    rng = np.random.default_rng(3)
    heights = 0.8 + rng.uniform(-0.04, 0.04, SHAPE)
    pts = cell_cloud(lambda r, c: heights[r, c], base, yaw)
    m = perception.deployment_map(
        pts[None],
        np.ones((1, len(pts)), bool),
        base[None],
        np.array([yaw]),
        SHAPE,
        SPACING,
        GAMMA,
        0.0,
    )
    assert abs(m.mean()) < 1e-12
    np.testing.assert_allclose(m[0], (heights - heights.mean()).ravel(), atol=1e-12)


def test_map_is_clipped_to_unit_range():
    """Two big levels 3 m apart: no outliers (sigma is large), centred -> +-1.5, clipped."""
    base, yaw = np.zeros(2), 0.0
    pts = cell_cloud(lambda r, c: 3.0 if r < 6 else 0.0, base, yaw)
    m = perception.deployment_map(
        pts[None],
        np.ones((1, len(pts)), bool),
        base[None],
        np.array([yaw]),
        SHAPE,
        SPACING,
        GAMMA,
        QUANTUM,
    ).reshape(SHAPE)
    assert (m[:6] == 1.0).all() and (m[6:] == -1.0).all()


def test_quantise_rounds_to_the_nearest_5_cm():
    values = np.array([0.0, 0.024, 0.026, -0.024, -0.026, 0.074, 0.076, 0.12, -0.13, 0.96, -1.0])
    expected = [0.0, 0.0, 0.05, 0.0, -0.05, 0.05, 0.1, 0.1, -0.15, 0.95, -1.0]
    np.testing.assert_allclose(perception.quantise(values, QUANTUM), expected, atol=1e-12)


def test_quantised_values_are_multiples_of_the_step_within_half_a_step():
    v = np.random.default_rng(1).uniform(-1, 1, 5000)
    q = perception.quantise(v, QUANTUM)
    k = q / QUANTUM
    np.testing.assert_allclose(k, np.round(k), atol=1e-9)
    assert np.abs(q - v).max() <= QUANTUM / 2 + 1e-12


def test_quantise_with_zero_step_is_identity():
    v = np.array([0.013, -0.4])
    np.testing.assert_array_equal(perception.quantise(v, 0.0), v)


# ---- the whole filter -------------------------------------------------------------------


def test_flat_floor_at_known_height_gives_an_all_zero_map():
    rng = np.random.default_rng(7)
    n_pts = 20000
    bases = np.array([[0.0, 0.0], [5.0, -3.0]])
    yaws = np.array([0.0, 2.2])
    clouds = []
    for base, yaw in zip(bases, yaws, strict=True):
        a, left = rng.uniform(-0.7, 0.7, (2, n_pts))  # covers the grid and beyond
        z = 0.37 + rng.normal(0, 0.004, n_pts)  # stereo-like noise at ~1 m
        clouds.append(to_world(a, left, z, base, yaw))
    pts = np.stack(clouds)
    valid = rng.random(pts.shape[:2]) >= 0.02
    m = perception.deployment_map(pts, valid, bases, yaws, SHAPE, SPACING, GAMMA, QUANTUM)
    assert m.shape == (2, CELLS)
    assert np.abs(m).max() == 0


def test_hand_made_stair_cloud_gives_the_quantised_step_pattern():
    """A flight rising ahead with 17 cm risers: rows 0-3 top step, 4-6 middle, 7-10 bottom.
    Balanced levels: mu is the middle step, no outliers, +-17 cm quantises to +-15 cm.
    Noise, far-away points, invalid points and a yawed, offset robot must not matter."""
    rng = np.random.default_rng(11)
    riser, floor = 0.17, 0.52
    level = np.repeat([2, 2, 2, 2, 1, 1, 1, 0, 0, 0, 0], 11).reshape(SHAPE)
    bases = np.array([[2.0, -1.0], [-4.0, 6.0]])
    yaws = np.array([np.pi / 2, -0.4])
    clouds, valids = [], []
    for base, yaw in zip(bases, yaws, strict=True):
        stair = cell_cloud(lambda r, c: floor + riser * level[r, c], base, yaw, rng, noise=0.005)
        far = to_world(rng.uniform(0.6, 2.0, 50), rng.uniform(-2, 2, 50), -3.0, base, yaw)
        bad = to_world(rng.uniform(-0.5, 0.5, 20), rng.uniform(-0.5, 0.5, 20), -9.0, base, yaw)
        clouds.append(np.concatenate([stair, far, bad]))
        valids.append(np.r_[np.ones(len(stair) + len(far), bool), np.zeros(len(bad), bool)])
    m = perception.deployment_map(
        np.stack(clouds), np.stack(valids), bases, yaws, SHAPE, SPACING, GAMMA, QUANTUM
    )
    expected = (0.15 * (level - 1)).ravel()
    for env in range(2):
        np.testing.assert_allclose(m[env], expected, atol=1e-9)
