"""The whole robot touches the world: a falling G1's torso, head and arms stop on the ground
instead of passing through it, on a plane and on a heightfield."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from lca.config import compose
from lca.sim.batch import BatchedSim
from lca.sim.scene import build_scene

UPPER = (
    "pelvis_collision",
    "torso_collision",
    "head_collision",
    "left_hand_collision",
    "right_hand_collision",
    "left_elbow_yaw_collision",
)


@pytest.mark.parametrize("terrain", ["flat", "uneven"])
def test_a_falling_robot_stops_on_the_ground(terrain):
    cfg = compose(["scale=smoke", f"terrain={terrain}", "terrain.resolution=0.02"])
    scene = build_scene(cfg)
    sim = BatchedSim(scene, 2, num_threads=1)
    sim.reset()
    qpos = sim.qpos.copy()
    pitch = np.radians([80.0, -80.0])  # thrown face down and on its back
    qpos[:, 3:7] = np.stack([np.cos(pitch / 2), 0 * pitch, np.sin(pitch / 2), 0 * pitch], 1)
    qpos[:, 2] += 0.3
    sim.qpos[:] = qpos
    sim.ctrl[:] = scene.home_joint_pos
    sim.forward()
    model = scene.model
    geoms = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, g) for g in UPPER]
    assert min(geoms) >= 0
    xpos = sim.batch.bind("geom_xpos")
    lowest = np.inf
    for _ in range(400):  # 2 s
        sim.step()
        pos = xpos[:, geoms]
        ground = scene.terrain.height_at(pos[..., 0], pos[..., 1])
        lowest = min(lowest, float((pos[..., 2] - ground).min()))
    assert lowest > -0.02, lowest  # geom centres: a body through the floor sinks far below
    final = xpos[:, geoms]
    assert (final[..., 2] < 0.5 + scene.terrain.heights.max()).all()  # it did fall
