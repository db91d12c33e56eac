"""The paper's four hardware tasks as simulation scenes, all dimensions from `conf/hardware`.

The robot starts at the origin facing +x. Static geometry (ground, steps, ledge platforms) is
a heightfield, so the task layer's exact height queries still hold; the hinged plank and the
soft mat are the project's own MJCF (assets/hardware/*.xml) attached on top of it, resized
from the config. `python -m lca.hardware.scenes` writes each whole scene as a binary model.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import mujoco
import numpy as np
from omegaconf import DictConfig

from lca.paths import assets_dir
from lca.sim.config import HardwareConfig
from lca.sim.scene import Scene, build_scene
from lca.sim.terrain import Terrain, Tile

ASSETS = assets_dir() / "hardware"
EXTENT_X = (-1.5, 6.0)  # m, heightfield extent around the task
EXTENT_Y = (-2.0, 2.0)


@dataclass
class HardwareTask:
    name: str
    terrain: Terrain
    goal_x: float  # base x at which the task counts as completed
    decorate: Callable[[mujoco.MjSpec], None] | None = None


def _grid(res: float) -> tuple[np.ndarray, np.ndarray]:
    xs = np.arange(EXTENT_X[0], EXTENT_X[1] + res / 2, res)
    ys = np.arange(EXTENT_Y[0], EXTENT_Y[1] + res / 2, res)
    return np.meshgrid(xs, ys)  # (rows=y, cols=x)


def _terrain(name: str, heights: np.ndarray, res: float) -> Terrain:
    return Terrain(heights, res, (EXTENT_X[0], EXTENT_Y[0]), [Tile(name, 0, 0, (0.0, 0.0))])


def stair_distance(x: np.ndarray, y: np.ndarray, skew_deg: float) -> np.ndarray:
    """Distance along the flight's climbing direction, rotated `skew_deg` from +x."""
    s = np.radians(skew_deg)
    return x * np.cos(s) + y * np.sin(s)


def stairs(cfg: HardwareConfig, up: bool) -> HardwareTask:
    st = cfg.stairs
    x, y = _grid(cfg.resolution)
    along = stair_distance(x, y, st.skew_deg) - cfg.approach
    # Points exactly on an edge belong to the step beyond it.
    level = np.clip(np.floor(along / st.landing + 1e-9) + 1, 0, st.steps)
    heights = st.riser * (level if up else st.steps - level)
    end_along = cfg.approach + st.steps * st.landing
    goal = end_along / np.cos(np.radians(st.skew_deg)) + cfg.goal_past
    name = "stair_ascent" if up else "stair_descent"
    return HardwareTask(name, _terrain(name, heights, cfg.resolution), goal)


def _platform(cfg: HardwareConfig, top: float) -> np.ndarray:
    x, _ = _grid(cfg.resolution)
    return np.where(x < cfg.approach, top, 0.0)


def _attach(spec: mujoco.MjSpec, asset: str, pos: list[float]) -> mujoco.MjSpec:
    """Load assets/hardware/<asset>.xml and attach its bodies to `spec` at `pos`."""
    child = mujoco.MjSpec.from_file(str(ASSETS / f"{asset}.xml"))
    frame = spec.worldbody.add_frame(pos=pos)
    for body in list(child.worldbody.bodies):
        frame.attach_body(body, "", "")
    return spec


def hinged_ledge(cfg: HardwareConfig) -> HardwareTask:
    """A platform `ledge_drop` above a plank that pivots about its centre."""
    p = cfg.plank
    plank_top = p.pivot_height + p.thickness / 2
    heights = _platform(cfg, plank_top + cfg.ledge_drop)
    centre_x = cfg.approach + p.gap + p.length / 2
    support_half = (p.pivot_height - p.thickness / 2 - 0.01) / 2

    def decorate(spec: mujoco.MjSpec) -> None:
        _attach(spec, "hinged_plank", [centre_x, 0.0, 0.0])
        support = spec.geom("pivot_support")
        support.size = [0.03, p.width / 2, support_half]
        support.pos = [0, 0, support_half]
        spec.body("plank").pos = [0, 0, p.pivot_height]
        hinge = spec.joint("plank_hinge")
        hinge.range = [-np.radians(p.tip_deg), np.radians(p.tip_deg)]
        hinge.damping = [p.damping, 0.0, 0.0]  # MjsJoint.damping is a 3-vector; [0] is linear
        plank = spec.geom("plank")
        plank.size = [p.length / 2, p.width / 2, p.thickness / 2]
        plank.mass = p.mass

    goal = cfg.approach + p.gap + p.length + cfg.goal_past
    return HardwareTask(
        "hinged_ledge", _terrain("hinged_ledge", heights, cfg.resolution), goal, decorate
    )


def soft_ledge(cfg: HardwareConfig) -> HardwareTask:
    """A platform `ledge_drop` above a compliant mat lying on the ground."""
    m = cfg.mat
    heights = _platform(cfg, m.thickness + cfg.ledge_drop)

    def decorate(spec: mujoco.MjSpec) -> None:
        _attach(spec, "soft_mat", [cfg.approach + m.length / 2, 0.0, 0.0])
        mat = spec.geom("soft_mat")
        mat.size = [m.length / 2, m.width / 2, m.thickness / 2]
        mat.pos = [0, 0, m.thickness / 2]
        mat.solref = list(m.solref)
        mat.solimp = list(m.solimp)

    goal = cfg.approach + m.length + cfg.goal_past
    return HardwareTask(
        "soft_ledge", _terrain("soft_ledge", heights, cfg.resolution), goal, decorate
    )


TASKS = {
    "stair_ascent": lambda cfg: stairs(cfg, up=True),
    "stair_descent": lambda cfg: stairs(cfg, up=False),
    "hinged_ledge": hinged_ledge,
    "soft_ledge": soft_ledge,
}


def build_task(cfg: DictConfig, name: str) -> tuple[HardwareTask, Scene]:
    task = TASKS[name](cfg.hardware)
    return task, build_scene(cfg, terrain=task.terrain, decorate=task.decorate)
