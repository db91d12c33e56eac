"""The paper's deployment perception filter: point cloud -> 11 x 11 policy heightmap.

1. downsample: each cell of the robot-centred, yaw-aligned grid takes the *minimum* valid
   point height (right under stair occlusions, where the higher step hides the lower one);
2. outlier rejection: cells with |g - mu| >= gamma * sigma are set to mu (mu, sigma over
   cells that received points; empty cells are set to mu too);
3. subtract mu, clip to [-1, 1], quantise to 5 cm steps.
"""

from __future__ import annotations

import numpy as np


def cell_indices(
    points: np.ndarray,
    base_xy: np.ndarray,
    yaw: np.ndarray,
    shape: tuple[int, int],
    spacing: float,
) -> tuple[np.ndarray, np.ndarray]:
    """(N, P) flat cell index of each point (row 0 farthest ahead, column 0 farthest left,
    as in `heightmap.grid_offsets`) and whether the point falls inside the grid."""
    rows, cols = shape
    dx = points[..., 0] - base_xy[:, None, 0]
    dy = points[..., 1] - base_xy[:, None, 1]
    cos, sin = np.cos(yaw)[:, None], np.sin(yaw)[:, None]
    ahead, left = cos * dx + sin * dy, -sin * dx + cos * dy
    i = np.rint((rows - 1) / 2 - ahead / spacing).astype(np.int64)
    j = np.rint((cols - 1) / 2 - left / spacing).astype(np.int64)
    inside = (i >= 0) & (i < rows) & (j >= 0) & (j < cols)
    return np.where(inside, i * cols + j, 0), inside


def min_height_grid(
    points: np.ndarray,
    valid: np.ndarray,
    base_xy: np.ndarray,
    yaw: np.ndarray,
    shape: tuple[int, int],
    spacing: float,
) -> tuple[np.ndarray, np.ndarray]:
    """(N, H*W) minimum point height per cell and (N, H*W) whether the cell got a point."""
    n = points.shape[0]
    cells = shape[0] * shape[1]
    index, inside = cell_indices(points, base_xy, yaw, shape, spacing)
    use = valid & inside
    flat = (np.arange(n)[:, None] * cells + index)[use]
    grid = np.full(n * cells, np.inf)
    np.minimum.at(grid, flat, points[..., 2][use])
    grid = grid.reshape(n, cells)
    return grid, np.isfinite(grid)


def reject_outliers(grid: np.ndarray, filled: np.ndarray, gamma: float):
    """Set outlier and empty cells to the grid mean; returns (grid, mu) with mu (N, 1)."""
    count = np.maximum(filled.sum(axis=1, keepdims=True), 1)
    values = np.where(filled, grid, 0.0)
    mu = values.sum(axis=1, keepdims=True) / count
    var = np.where(filled, (grid - mu) ** 2, 0.0).sum(axis=1, keepdims=True) / count
    sigma = np.sqrt(var)
    outlier = np.abs(np.where(filled, grid, mu) - mu) >= gamma * sigma
    outlier &= sigma > 0  # a perfectly flat grid has no outliers
    return np.where(filled & ~outlier, grid, mu), mu


def quantise(values: np.ndarray, step: float) -> np.ndarray:
    return np.round(values / step) * step if step > 0 else values


def deployment_map(
    points: np.ndarray,
    valid: np.ndarray,
    base_xy: np.ndarray,
    yaw: np.ndarray,
    shape: tuple[int, int],
    spacing: float,
    gamma: float,
    step: float,
) -> np.ndarray:
    """The whole filter: (N, H*W) map, zero-mean, in [-1, 1], in multiples of `step`."""
    grid, filled = min_height_grid(points, valid, base_xy, yaw, shape, spacing)
    grid, mu = reject_outliers(grid, filled, gamma)
    return quantise(np.clip(grid - mu, -1.0, 1.0), step)
