"""No unit walks off the world: from every spawn, a straight 20 s walk at the fastest command
(with a 1.5x margin for overshoot) in any heading stays above ground, at every scale."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from lca.config import compose
from lca.sim.scene import build_scene

HEADINGS = np.linspace(0, 2 * np.pi, 16, endpoint=False)


def _ground_below(model: mujoco.MjModel, data: mujoco.MjData, x: float, y: float) -> bool:
    geomid = np.zeros(1, dtype=np.int32)
    # geom group 0 holds the terrain (robot geoms are in groups 2-4)
    groups = np.array([1, 0, 0, 0, 0, 0], dtype=np.uint8)
    dist = mujoco.mj_ray(
        model, data, np.array([x, y, 50.0]), np.array([0, 0, -1.0]), groups, 1, -1, geomid
    )
    return dist >= 0


@pytest.mark.parametrize("scale", ["cpu", "paper"])
@pytest.mark.parametrize("terrain", ["mixed", "flat"])
def test_a_20_s_walk_in_any_heading_stays_on_the_ground(scale: str, terrain: str) -> None:
    cfg = compose([f"scale={scale}", f"terrain={terrain}", "terrain.resolution=0.1"])
    c = cfg.task.commands
    speed = np.hypot(max(map(abs, c.lin_vel_x)), max(map(abs, c.lin_vel_y)))
    speed = max(speed, max(cfg.eval.command_x))
    travel = 1.5 * speed * cfg.task.episode_length_s
    scene = build_scene(cfg)
    model, data = scene.model, mujoco.MjData(scene.model)
    mujoco.mj_forward(model, data)
    spread = cfg.task.reset.base_xy_noise
    for cx, cy in scene.terrain.tile_centres():
        for h in HEADINGS:
            for s in (-spread, spread):
                x, y = cx + s + travel * np.cos(h), cy + s + travel * np.sin(h)
                assert _ground_below(model, data, x, y), (scale, terrain, (cx, cy), h)
    # and the world is not infinite by accident: far beyond the apron there is nothing
    if terrain == "mixed":
        sx, sy = scene.terrain.size
        assert not _ground_below(model, data, sx + cfg.terrain.apron + 5.0, 0.0)
