"""Robot-centred, yaw-aligned terrain height grids for the actor and the critic.

Values are terrain heights at grid points, then (paper) the grid mean is subtracted and the
result clipped to [-1, 1]. The actor's map also gets uniform noise of the difficulty's
magnitude and random cell dropout (a dropped cell reads as the mean, i.e. 0).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from lca.arrays import Array, draw, like, namespace
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


def sample_heights(terrain: Terrain, base_xy: Array, yaw: Array, offsets: Array) -> Array:
    """(N, P) terrain heights at offsets rotated by each base's yaw (NumPy or torch)."""
    xp = namespace(base_xy, yaw)
    offsets = like(offsets, base_xy)
    heading = xp.stack([xp.cos(yaw), xp.sin(yaw)], axis=1)  # (N, 2)
    # x = bx + cos ox - sin oy, y = by + sin ox + cos oy: two (N, 2) @ (2, P) products
    x = base_xy[:, :1] + heading @ xp.stack([offsets[:, 0], -offsets[:, 1]])
    y = base_xy[:, 1:2] + heading @ xp.stack([offsets[:, 1], offsets[:, 0]])
    return terrain.height_at(x, y)


def normalise(heights: Array, valid: Array | None = None) -> Array:
    """Subtract each grid's mean (over valid cells), zero invalid cells, clip to [-1, 1]."""
    xp = namespace(heights)
    if valid is None:
        centred = heights - xp.mean(heights, axis=1, keepdims=True)
    else:
        count = xp.clip(xp.sum(valid, axis=1, keepdims=True), min=1)
        mean = xp.sum(xp.where(valid, heights, 0.0), axis=1, keepdims=True) / count
        centred = xp.where(valid, heights - mean, 0.0)
    return xp.clip(centred, min=-1.0, max=1.0)


def actor_map(heights: Array, noise: float, dropout: float, rng: Any) -> Array:
    """Noisy, sparse map: uniform noise of magnitude `noise`, cells dropped with `dropout`
    (`rng`: a NumPy Generator, or a torch.Generator on the tensors' device)."""
    shape = tuple(heights.shape)
    noisy = heights + draw(rng, -noise, noise, shape, heights) if noise > 0 else heights
    valid = draw(rng, 0.0, 1.0, shape, heights) >= dropout if dropout > 0 else None
    return normalise(noisy, valid)
