"""Contacts on the boxes representation against the heightfield, scripted in plain MuJoCo on
one full-size hill (stairs_down, medium): the G1 standing with both feet on a tread, standing
with its toes over a riser edge, and falling face down onto the stairs. The heightfield's
riser is a 1 cm ramp and the boxes' vertical: the poses agree within 3-5 mm, a fall's first
contact within one physics step and 1 cm."""

from __future__ import annotations

import functools

import mujoco
import numpy as np
import pytest

from lca.config import compose
from lca.sim.scene import Scene, build_scene

# 30 Hz PD holds a passive stand (tests/conftest.py)
HILL = [
    "terrain=stairs_down",
    "terrain.rows=1",
    "terrain.cols=1",
    "terrain.apron=2",
    "robot.natural_frequency_hz=30",
]


@functools.cache
def hill(representation: str) -> Scene:
    return build_scene(compose([*HILL, f"terrain.representation={representation}"]))


def riser_edge(scene: Scene) -> float:
    """x offset from the tile centre of the third riser on the +x side (downhill past it)."""
    edges = scene.terrain.tiles[0].cells[0]
    return float(edges[edges > 0][2])


def start(scene: Scene, x: float, pitch: float = 0.0, above: float | None = None):
    """MjData with the robot at home, `x` m from the tile centre, pitched about y, its base
    `above` m over the ground (default: standing height)."""
    model = scene.model
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, scene.home_key)
    cx, cy = scene.terrain.tiles[0].centre
    ground = float(scene.terrain.height_at(cx + x, cy))
    data.qpos[:3] = [cx + x, cy, ground + (scene.base_height if above is None else above)]
    data.qpos[3:7] = [np.cos(pitch / 2), 0.0, np.sin(pitch / 2), 0.0]
    return model, data


def stand(representation: str, x: float, seconds: float) -> np.ndarray:
    scene = hill(representation)
    model, data = start(scene, x)
    for _ in range(int(round(seconds / model.opt.timestep))):
        mujoco.mj_step(model, data)
    return data.qpos[:7].copy()


@pytest.mark.parametrize(
    ("case", "offset", "seconds", "tolerance"),
    [
        # the ankle 0.2 m before the riser edge: both soles on one 0.31 m tread
        ("foot on a tread", -0.2, 1.0, 0.005),
        # the ankle 5 cm before the edge: the toe spheres (13 cm ahead) hang over the riser
        ("toes over a riser edge", -0.05, 0.4, 0.003),
    ],
)
def test_standing_on_stairs_as_on_the_heightfield(case, offset, seconds, tolerance) -> None:
    x = riser_edge(hill("boxes")) + offset
    boxes, field = stand("boxes", x, seconds), stand("heightfield", x, seconds)
    np.testing.assert_allclose(boxes[:3], field[:3], atol=tolerance, err_msg=case)
    np.testing.assert_allclose(boxes[3:], field[3:], atol=0.01, err_msg=case)  # quaternion
    assert boxes[2] > hill("boxes").terrain.height_at(boxes[0], boxes[1]) + 0.6, "fell"


def fall(representation: str) -> tuple[str, float, np.ndarray]:
    """Face down from 0.6 m over the stairs, head uphill: the first robot geom to touch, when,
    and the torso's position 50 ms later."""
    scene = hill(representation)
    model, data = start(scene, riser_edge(scene) - 0.3, pitch=-np.pi / 2, above=0.6)
    torso = model.body("torso_link").id
    first = None
    while data.time < 1.0:
        mujoco.mj_step(model, data)
        if first is None and data.ncon:
            geoms = [g for c in data.contact[: data.ncon] for g in c.geom]
            names = {mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_GEOM, g) for g in geoms}
            robot = sorted(n for n in names if not n.startswith(("terrain", "apron")))
            first = (robot[0], data.time)
        if first is not None and data.time >= first[1] + 0.05:
            return first[0], first[1], data.xpos[torso].copy()
    raise AssertionError("the robot never touched the stairs")


def test_torso_falling_onto_stairs_as_on_the_heightfield() -> None:
    geom_b, t_b, torso_b = fall("boxes")
    geom_h, t_h, torso_h = fall("heightfield")
    assert "torso" in geom_b or "head" in geom_b, geom_b
    assert geom_b == geom_h
    assert abs(t_b - t_h) <= 0.005  # one physics step
    np.testing.assert_allclose(torso_b, torso_h, atol=0.01)
