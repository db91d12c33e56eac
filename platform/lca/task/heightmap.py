"""Robot-centred, yaw-aligned terrain height grids for the actor and the critic.

Values are terrain heights at grid points, then (paper) the grid mean is subtracted and the
result clipped to [-1, 1]. The actor's map also gets uniform noise of the difficulty's
magnitude and random cell dropout (a dropped cell reads as the mean, i.e. 0).
"""

from __future__ import annotations

import numpy as np

from lca.sim.terrain import Terrain


def grid_offsets(shape: tuple[int, int], spacing: float) -> np.ndarray:
    """(H*W, 2) x, y offsets in the base yaw frame; row i is +x ahead, column j is +y left.

    Row 0 is the farthest ahead, so the image reads like a top view with forward up.
    """
    rows, cols = shape
    xs = (np.arange(rows)[::-1] - (rows - 1) / 2) * spacing
    ys = (np.arange(cols)[::-1] - (cols - 1) / 2) * spacing
    gx, gy = np.meshgrid(xs, ys, indexing="ij")
    return np.stack([gx.ravel(), gy.ravel()], axis=1)


def sample_heights(
    terrain: Terrain, base_xy: np.ndarray, yaw: np.ndarray, offsets: np.ndarray
) -> np.ndarray:
    """(N, P) terrain heights at offsets rotated by each base's yaw."""
    cos, sin = np.cos(yaw)[:, None], np.sin(yaw)[:, None]
    x = base_xy[:, :1] + cos * offsets[None, :, 0] - sin * offsets[None, :, 1]
    y = base_xy[:, 1:2] + sin * offsets[None, :, 0] + cos * offsets[None, :, 1]
    return terrain.height_at(x, y)


def normalise(heights: np.ndarray, valid: np.ndarray | None = None) -> np.ndarray:
    """Subtract each grid's mean (over valid cells), zero invalid cells, clip to [-1, 1]."""
    if valid is None:
        centred = heights - heights.mean(axis=1, keepdims=True)
    else:
        count = np.maximum(valid.sum(axis=1, keepdims=True), 1)
        mean = np.where(valid, heights, 0.0).sum(axis=1, keepdims=True) / count
        centred = np.where(valid, heights - mean, 0.0)
    return np.clip(centred, -1.0, 1.0)


def actor_map(
    heights: np.ndarray, noise: float, dropout: float, rng: np.random.Generator
) -> np.ndarray:
    """Noisy, sparse map: uniform noise of magnitude `noise`, cells dropped with `dropout`."""
    noisy = heights + rng.uniform(-noise, noise, heights.shape) if noise > 0 else heights
    valid = rng.random(heights.shape) >= dropout if dropout > 0 else None
    return normalise(noisy, valid)
