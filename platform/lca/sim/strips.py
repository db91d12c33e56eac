"""Ground that is a step function of one horizontal direction, built from rotated boxes.

The hardware tasks' static geometry (a skewed flight of stairs, a ledge's platform) is
constant along lines perpendicular to one direction: heights change only at `edges` of the
coordinate `along = x cos(yaw) + y sin(yaw)`. Each step becomes one box rotated by `yaw`, its
top at the step's height, so risers are vertical and `height_at` is exact. As a heightfield
the same ground made every depth-camera ray test thousands of 1 cm cells (MuJoCo's ray-hfield
test walks the ray's whole bounding rectangle): `python -m lca.bench hardware` measures both.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from lca.arrays import Array, arrays, device_of, namespace

BASE_DEPTH = 0.5  # m of solid below the lowest ground point (boxes and heightfields alike)


@dataclass
class Strips:
    yaw: float  # rad, the direction along which the height changes
    edges: np.ndarray  # (K,) ascending `along` values (m) where the height changes
    # (K + 1,) heights: before edges[0], between consecutive edges, from edges[-1] on; a
    # point exactly on an edge takes the step beyond it
    heights: np.ndarray

    def along(self, x: Array, y: Array) -> Array:
        return x * float(np.cos(self.yaw)) + y * float(np.sin(self.yaw))

    def height_at(self, x: Array, y: Array) -> Array:
        """The top of the step under world points (NumPy or torch, any shape)."""
        x, y = arrays(x, y)
        xp = namespace(x, y)
        along = self.along(x, y)
        step = xp.zeros(along.shape, dtype=xp.int64, device=device_of(along))
        for edge in self.edges:
            step += xp.astype(along >= float(edge), xp.int64)
        heights = xp.asarray(self.heights, dtype=along.dtype, device=device_of(along))
        return xp.reshape(xp.take(heights, xp.reshape(step, (-1,))), along.shape)


def add_strips(
    spec: mujoco.MjSpec, strips: Strips, corners: np.ndarray, rgba: list, collide: dict
) -> None:
    """The lowest step as an infinite plane (terrain_floor) and every higher step as one box
    (terrain_strip<i>) across the world rectangle whose (4, 2) `corners` are given, the outer
    ones to its far corners. A plane, not a box, under the lowest step: MuJoCo's box-box test
    let a falling plank (the hinged ledge) sink 12 degrees past the ground in one step."""
    floor = float(strips.heights.min())
    spec.worldbody.add_geom(
        name="terrain_floor",
        type=mujoco.mjtGeom.mjGEOM_PLANE,
        size=[0, 0, 1],
        pos=[0, 0, floor],
        rgba=rgba,
        **collide,
    )
    c, s = np.cos(strips.yaw), np.sin(strips.yaw)
    along, across = corners @ np.array([c, s]), corners @ np.array([-s, c])
    bounds = np.concatenate([[along.min()], strips.edges, [along.max()]])
    base = floor - BASE_DEPTH
    mid_across, half_across = (across.min() + across.max()) / 2, np.ptp(across) / 2
    quat = [np.cos(strips.yaw / 2), 0.0, 0.0, np.sin(strips.yaw / 2)]
    for i, top in enumerate(strips.heights):
        a0, a1 = max(bounds[i], along.min()), min(bounds[i + 1], along.max())
        if top <= floor or a1 <= a0:
            continue  # the floor's own step, or a step outside the rectangle
        mid_along = (a0 + a1) / 2
        spec.worldbody.add_geom(
            name=f"terrain_strip{i}",
            type=mujoco.mjtGeom.mjGEOM_BOX,
            size=[(a1 - a0) / 2, half_across, (top - base) / 2],
            pos=[mid_along * c - mid_across * s, mid_along * s + mid_across * c, (top + base) / 2],
            quat=quat,
            rgba=rgba,
            **collide,
        )
