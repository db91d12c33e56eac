"""Robot-centred, yaw-aligned height grids over hand-built terrains; normalisation; noise."""

from __future__ import annotations

import math

import numpy as np
import pytest

from lca.config import compose
from lca.sim.terrain import Terrain
from lca.task import heightmap

RES = 0.01
STEP_X = 1.0  # the step rises by STEP_H at x = 1.0 m
STEP_H = 0.2


@pytest.fixture(scope="module")
def step_terrain() -> Terrain:
    """3 m x 3 m, origin (0, 0): height 0 for x < 1.0 and 0.2 for x >= 1.0."""
    n = 301
    xs = np.arange(n) * RES
    heights = np.where(xs >= STEP_X - 1e-9, STEP_H, 0.0)[None, :].repeat(n, axis=0)
    return Terrain(heights=heights, resolution=RES, origin=(0.0, 0.0), tiles=[])


@pytest.fixture(scope="module")
def plane_terrain() -> Terrain:
    """The plane h = 0.3 x - 0.2 y + 0.1 over [-2, 2]^2, exact under linear interpolation."""
    n = 401
    xs = -2.0 + np.arange(n) * RES
    gx, gy = np.meshgrid(xs, xs, indexing="xy")  # heights[r, c] at x = xs[c], y = xs[r]
    heights = 0.3 * gx - 0.2 * gy + 0.1
    return Terrain(heights=heights, resolution=RES, origin=(-2.0, -2.0), tiles=[])


def grid(terrain: Terrain, xy, yaw, shape=(11, 11), spacing=0.1) -> np.ndarray:
    offsets = heightmap.grid_offsets(shape, spacing)
    h = heightmap.sample_heights(terrain, np.array([xy], float), np.array([yaw], float), offsets)
    assert h.shape == (1, shape[0] * shape[1])
    return h.reshape(shape)


# ---- grid geometry -------------------------------------------------------------------------
def test_actor_grid_offsets_row0_ahead_col0_left():
    off = heightmap.grid_offsets((11, 11), 0.1).reshape(11, 11, 2)
    np.testing.assert_allclose(off[0, 0], [0.5, 0.5], atol=1e-12)  # farthest ahead, left
    np.testing.assert_allclose(off[10, 10], [-0.5, -0.5], atol=1e-12)  # behind, right
    np.testing.assert_allclose(off[5, 5], [0.0, 0.0], atol=1e-12)  # the base
    np.testing.assert_allclose(off[0, 5], [0.5, 0.0], atol=1e-12)
    np.testing.assert_allclose(off[5, 0], [0.0, 0.5], atol=1e-12)
    # rows vary x only, columns y only, in 0.1 m steps: a 1.0 m x 1.0 m grid
    np.testing.assert_allclose(np.diff(off[:, 3, 0]), -0.1)
    np.testing.assert_allclose(np.diff(off[3, :, 1]), -0.1)
    np.testing.assert_allclose(off[:, :, 1].std(axis=0), 0, atol=1e-12)


def test_critic_grid_offsets_cover_1p5_m_without_a_centre_cell():
    off = heightmap.grid_offsets((16, 16), 0.1)
    assert off.shape == (256, 2)
    np.testing.assert_allclose(off.max(axis=0), [0.75, 0.75])
    np.testing.assert_allclose(off.min(axis=0), [-0.75, -0.75])
    np.testing.assert_allclose(off.mean(axis=0), [0.0, 0.0], atol=1e-12)
    assert np.abs(off).min() == pytest.approx(0.05)


# ---- a step ahead, behind, to the side ----------------------------------------------------
def test_step_appears_in_the_rows_ahead_when_facing_it(step_terrain):
    h = grid(step_terrain, (0.95, 1.5), 0.0)  # points at x = 0.45 ... 1.45
    expected = np.zeros((11, 11))
    expected[:5] = STEP_H  # rows 0..4: 0.5 .. 0.1 m ahead, x >= 1.05
    np.testing.assert_allclose(h, expected, atol=1e-9)


def test_step_appears_in_the_rows_behind_when_facing_away(step_terrain):
    h = grid(step_terrain, (0.95, 1.5), math.pi)
    expected = np.zeros((11, 11))
    expected[6:] = STEP_H  # rows 6..10 are 0.1 .. 0.5 m behind, i.e. at larger x
    np.testing.assert_allclose(h, expected, atol=1e-9)


def test_step_appears_in_the_right_columns_when_facing_plus_y(step_terrain):
    h = grid(step_terrain, (0.95, 1.5), math.pi / 2)  # left is -x, right is +x
    expected = np.zeros((11, 11))
    expected[:, 6:] = STEP_H
    np.testing.assert_allclose(h, expected, atol=1e-9)


def test_step_appears_in_the_left_columns_when_facing_minus_y(step_terrain):
    h = grid(step_terrain, (0.95, 1.5), -math.pi / 2)  # left is +x
    expected = np.zeros((11, 11))
    expected[:, :5] = STEP_H
    np.testing.assert_allclose(h, expected, atol=1e-9)


def test_step_far_away_is_not_seen(step_terrain):
    np.testing.assert_allclose(grid(step_terrain, (0.3, 1.5), 0.0), 0.0, atol=1e-12)
    np.testing.assert_allclose(grid(step_terrain, (2.0, 1.5), 1.0), STEP_H, atol=1e-12)


def test_step_normalised_map_is_zero_mean_and_keeps_the_step_size(step_terrain):
    h = grid(step_terrain, (0.95, 1.5), 0.0).reshape(1, -1)
    m = heightmap.normalise(h).reshape(11, 11)
    # 55 of 121 cells at 0.2: mean 0.2 * 55 / 121
    mean = STEP_H * 55 / 121
    np.testing.assert_allclose(m[:5], STEP_H - mean, atol=1e-9)
    np.testing.assert_allclose(m[5:], -mean, atol=1e-9)


@pytest.mark.parametrize("yaw", [0.0, 0.3, 1.2, -2.5, math.pi])
def test_rotated_grid_on_a_plane(plane_terrain, yaw):
    """At a general yaw every cell reads the plane at base + R(yaw) offset."""
    base = np.array([0.37, -0.21])
    h = grid(plane_terrain, base, yaw)
    for i, j in [(0, 0), (0, 10), (10, 0), (10, 10), (5, 5), (2, 7)]:
        ahead, left = (5 - i) * 0.1, (5 - j) * 0.1
        x = base[0] + math.cos(yaw) * ahead - math.sin(yaw) * left
        y = base[1] + math.sin(yaw) * ahead + math.cos(yaw) * left
        assert h[i, j] == pytest.approx(0.3 * x - 0.2 * y + 0.1, abs=1e-9), (i, j)


def test_sample_heights_is_per_env(plane_terrain):
    offsets = heightmap.grid_offsets((3, 3), 0.5)
    xy = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 0.0]])
    yaw = np.array([0.0, 0.0, math.pi / 2])
    h = heightmap.sample_heights(plane_terrain, xy, yaw, offsets)
    # cell (0, 1): 0.5 m ahead. env 0 at x = 0.5; env 1 at x = 1.5; env 2 at y = 0.5
    np.testing.assert_allclose(h[:, 1], [0.25, 0.55, 0.0], atol=1e-9)


# ---- normalisation -------------------------------------------------------------------------
def test_normalise_subtracts_each_grid_mean_and_clips():
    h = np.array([[1.0, 2.0, 3.0, 6.0], [0.1, 0.2, 0.3, 0.6], [5.0, 5.0, 5.0, 5.0]])
    out = heightmap.normalise(h)
    np.testing.assert_allclose(out[0], [-1.0, -1.0, 0.0, 1.0])  # -2, -1, 0, 3 clipped
    np.testing.assert_allclose(out[1], [-0.2, -0.1, 0.0, 0.3], atol=1e-12)
    np.testing.assert_array_equal(out[2], 0.0)


def test_normalise_is_zero_mean_within_the_clip_range():
    rng = np.random.default_rng(1)
    h = rng.uniform(-0.4, 0.4, (50, 121)) + rng.normal(0, 3, (50, 1))  # per-grid offsets
    out = heightmap.normalise(h)
    np.testing.assert_allclose(out.mean(axis=1), 0.0, atol=1e-12)
    assert np.abs(out).max() <= 0.8 + 1e-12


def test_normalise_clips_to_unit_range():
    rng = np.random.default_rng(2)
    out = heightmap.normalise(rng.normal(0, 5, (20, 121)))
    assert out.max() == 1.0 and out.min() == -1.0


def test_normalise_mean_over_valid_cells_and_dropped_cells_read_zero():
    h = np.array([[0.1, 0.2, 5.0, 0.3], [0.1, 0.2, 5.0, 0.3]])
    valid = np.array([[True, True, False, True], [True, True, True, True]])
    out = heightmap.normalise(h, valid)
    # env 0: mean of 0.1, 0.2, 0.3 = 0.2; the dropped outlier reads exactly 0
    np.testing.assert_allclose(out[0], [-0.1, 0.0, 0.0, 0.1], atol=1e-12)
    assert out[0, 2] == 0.0
    # env 1: mean 1.4, so -1.3, -1.2, 3.6, -1.1 clip to -1, -1, 1, -1
    np.testing.assert_array_equal(out[1], [-1.0, -1.0, 1.0, -1.0])


def test_normalise_with_every_cell_dropped_is_zero():
    out = heightmap.normalise(np.full((2, 5), 3.0), np.zeros((2, 5), bool))
    np.testing.assert_array_equal(out, 0.0)


def test_actor_map_dropout_share_and_zero_mean():
    rng = np.random.default_rng(3)
    ramp = np.linspace(-0.4, 0.4, 121) + 0.001 * np.sin(np.arange(121))  # no repeated values
    heights = np.tile(ramp, (400, 1)) + rng.normal(0, 2, (400, 1))
    out = heightmap.actor_map(heights, noise=0.0, dropout=0.25, rng=rng)
    zeros = out == 0.0
    assert zeros.mean() == pytest.approx(0.25, abs=0.02)
    # valid cells are centred on their own mean, dropped cells add 0: every grid sums to 0
    np.testing.assert_allclose(out.sum(axis=1), 0.0, atol=1e-9)
    # without dropout and noise no cell is dropped
    clean = heightmap.actor_map(heights, noise=0.0, dropout=0.0, rng=rng)
    np.testing.assert_allclose(clean, heightmap.normalise(heights))
    assert (clean != 0).all()


# ---- noise per difficulty (paper table "Environment parameters") --------------------------
@pytest.mark.parametrize(("difficulty", "noise"), [("medium", 0.10), ("hard", 0.30)])
def test_actor_map_noise_magnitude_per_difficulty(difficulty, noise):
    cfg = compose([f"difficulty={difficulty}"])
    assert cfg.difficulty.height_noise == pytest.approx(noise)
    rng = np.random.default_rng(4)
    flat = np.zeros((200, 121))
    out = heightmap.actor_map(flat, float(cfg.difficulty.height_noise), 0.0, rng)
    # U(-a, a) minus the grid mean: each grid spans at most 2a, near 2a with 121 draws
    span = out.max(axis=1) - out.min(axis=1)
    assert span.max() <= 2 * noise
    assert span.min() >= 1.6 * noise
    np.testing.assert_allclose(out.mean(axis=1), 0.0, atol=1e-12)
    # std of U(-a, a) is a / sqrt(3); the mean removal costs a factor sqrt(120/121)
    expected_std = noise / math.sqrt(3) * math.sqrt(120 / 121)
    assert out.std() == pytest.approx(expected_std, rel=0.03)
