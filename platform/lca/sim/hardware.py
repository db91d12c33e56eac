"""The paper's four hardware tasks as simulation scenes, all dimensions from `conf/hardware`.

The robot starts at the origin facing +x. Static geometry (ground, steps, ledge platforms) is
rotated boxes (`lca.sim.strips`, or a heightfield: `hardware.representation`), with exact
height queries for the task layer either way; the hinged plank and the
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
from lca.sim.strips import Strips
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


def _terrain(name: str, cfg: HardwareConfig, ground: Strips) -> Terrain:
    """The task's ground: `ground` as rotated boxes (`hardware.representation=strips`), or
    its 1 cm samples as a heightfield; the samples draw previews either way."""
    x, y = _grid(cfg.resolution)
    heights = np.asarray(ground.height_at(x, y), dtype=float)
    strips = ground if cfg.representation == "strips" else None
    tiles = [Tile(name, 0, 0, (0.0, 0.0))]
    return Terrain(heights, cfg.resolution, (EXTENT_X[0], EXTENT_Y[0]), tiles, strips=strips)


def stairs(cfg: HardwareConfig, up: bool) -> HardwareTask:
    st = cfg.stairs
    # the first riser `approach` along the climbing direction, then one per landing
    edges = cfg.approach + st.landing * np.arange(st.steps)
    levels = np.arange(st.steps + 1) if up else st.steps - np.arange(st.steps + 1)
    ground = Strips(float(np.radians(st.skew_deg)), edges, st.riser * levels)
    end_along = cfg.approach + st.steps * st.landing
    goal = end_along / np.cos(np.radians(st.skew_deg)) + cfg.goal_past
    name = "stair_ascent" if up else "stair_descent"
    return HardwareTask(name, _terrain(name, cfg, ground), goal)


def _platform(top: float, cfg: HardwareConfig) -> Strips:
    """A platform `top` high up to x = approach, the ground at 0 beyond."""
    return Strips(0.0, np.array([cfg.approach]), np.array([top, 0.0]))


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
    ground = _platform(plank_top + cfg.ledge_drop, cfg)
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
        spec.option.ls_iterations = max(spec.option.ls_iterations, p.ls_iterations)

    goal = cfg.approach + p.gap + p.length + cfg.goal_past
    return HardwareTask("hinged_ledge", _terrain("hinged_ledge", cfg, ground), goal, decorate)


def soft_ledge(cfg: HardwareConfig) -> HardwareTask:
    """A platform `ledge_drop` above a compliant mat lying on the ground."""
    m = cfg.mat
    ground = _platform(m.thickness + cfg.ledge_drop, cfg)

    def decorate(spec: mujoco.MjSpec) -> None:
        _attach(spec, "soft_mat", [cfg.approach + m.length / 2, 0.0, 0.0])
        mat = spec.geom("soft_mat")
        mat.size = [m.length / 2, m.width / 2, m.thickness / 2]
        mat.pos = [0, 0, m.thickness / 2]
        mat.solref = list(m.solref)
        mat.solimp = list(m.solimp)

    goal = cfg.approach + m.length + cfg.goal_past
    return HardwareTask("soft_ledge", _terrain("soft_ledge", cfg, ground), goal, decorate)


TASKS = {
    "stair_ascent": lambda cfg: stairs(cfg, up=True),
    "stair_descent": lambda cfg: stairs(cfg, up=False),
    "hinged_ledge": hinged_ledge,
    "soft_ledge": soft_ledge,
}


def build_task(cfg: DictConfig, name: str) -> tuple[HardwareTask, Scene]:
    task = TASKS[name](cfg.hardware)
    return task, build_scene(cfg, terrain=task.terrain, decorate=task.decorate)
