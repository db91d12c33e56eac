"""Compose the G1 and the terrain (boxes, a heightfield or a plane) into one compiled MuJoCo
model."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import mujoco
import numpy as np
from omegaconf import DictConfig

from lca.sim import robot as g1
from lca.sim.config import RobotConfig, SimConfig
from lca.sim.relief import BASE_DEPTH, add_boxes
from lca.sim.strips import add_strips
from lca.sim.terrain import Terrain, generate

INTEGRATORS = {
    "euler": mujoco.mjtIntegrator.mjINT_EULER,
    "implicit": mujoco.mjtIntegrator.mjINT_IMPLICIT,
    "implicitfast": mujoco.mjtIntegrator.mjINT_IMPLICITFAST,
    "rk4": mujoco.mjtIntegrator.mjINT_RK4,
}
CONES = {"pyramidal": mujoco.mjtCone.mjCONE_PYRAMIDAL, "elliptic": mujoco.mjtCone.mjCONE_ELLIPTIC}


@dataclass
class Scene:
    model: mujoco.MjModel
    terrain: Terrain
    joint_names: list[str]
    home_qpos: np.ndarray  # full qpos of the `home` keyframe (base at the first tile centre)
    home_joint_pos: np.ndarray  # (29,) default joint angles, also the home ctrl
    base_height: float  # base z above the ground in the home pose

    @property
    def home_key(self) -> int:
        return mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_KEY, "home")


def apply_sim_options(spec: mujoco.MjSpec, cfg: SimConfig) -> None:
    spec.option.timestep = cfg.timestep
    spec.option.integrator = INTEGRATORS[cfg.integrator]
    spec.option.cone = CONES[cfg.cone]
    spec.option.iterations = cfg.iterations
    spec.option.ls_iterations = cfg.ls_iterations
    spec.visual.global_.bvactive = int(cfg.bvactive)


def add_terrain(
    spec: mujoco.MjSpec, terrain: Terrain, apron: float = 0.0, plane: bool = False
) -> None:
    """Add `terrain` as its representation says: box geoms (with the flat border as four
    boxes around the tiles) or one hfield geom (MuJoCo stores heights normalised to [0, 1]);
    with `plane` (an all-flat terrain), an infinite plane at height 0. `apron` > 0 surrounds
    it with flat ground at height 0 (its border's height) that far on every side."""
    rgba = [0.45, 0.5, 0.55, 1.0]
    collide = {"contype": g1.TERRAIN_CONTYPE, "conaffinity": g1.TERRAIN_CONAFFINITY, "condim": 3}
    if plane:
        spec.worldbody.add_geom(
            name="terrain", type=mujoco.mjtGeom.mjGEOM_PLANE, size=[0, 0, 1], rgba=rgba, **collide
        )
        return
    (x0, y0), (sx, sy) = terrain.origin, terrain.size
    if terrain.strips is not None:
        corners = np.array([[x0, y0], [x0 + sx, y0], [x0, y0 + sy], [x0 + sx, y0 + sy]])
        add_strips(spec, terrain.strips, corners, rgba, collide)
        if apron > 0:
            _add_apron(spec, (x0, y0), (sx, sy), apron, rgba, collide)
        return
    if terrain.representation == "boxes":
        add_boxes(spec, terrain, rgba, collide)
        # the border (inside the sample grid) joins the apron: flat ground around the tiles
        border = -x0
        if border + apron > 0:
            tiles = (sx - 2 * border, sy - 2 * border)
            _add_apron(spec, (0.0, 0.0), tiles, border + apron, rgba, collide)
        return
    h = terrain.heights
    low, span = float(h.min()), float(np.ptp(h))
    span = max(span, 1e-3)  # MuJoCo needs a positive elevation range even for flat ground
    nrow, ncol = h.shape
    sx, sy = terrain.size
    spec.add_hfield(
        name="terrain",
        size=[sx / 2, sy / 2, span, BASE_DEPTH],
        nrow=nrow,
        ncol=ncol,
        userdata=((h - low) / span).astype(np.float32).ravel(),
    )
    cx, cy = terrain.centre
    spec.worldbody.add_geom(
        name="terrain",
        type=mujoco.mjtGeom.mjGEOM_HFIELD,
        hfieldname="terrain",
        pos=[cx, cy, low],
        rgba=rgba,
        **collide,
    )
    if apron > 0:
        _add_apron(spec, (x0, y0), (sx, sy), apron, rgba, collide)


def _add_apron(spec, origin, size, apron: float, rgba, collide) -> None:
    """Four boxes, top face at z = 0, framing the rectangle at `origin` of `size` (x strips
    span the corners)."""
    (x0, y0), (sx, sy) = origin, size
    depth = BASE_DEPTH
    for i, (cx, cy, hx, hy) in enumerate(
        [
            (x0 - apron / 2, y0 + sy / 2, apron / 2, sy / 2 + apron),
            (x0 + sx + apron / 2, y0 + sy / 2, apron / 2, sy / 2 + apron),
            (x0 + sx / 2, y0 - apron / 2, sx / 2, apron / 2),
            (x0 + sx / 2, y0 + sy + apron / 2, sx / 2, apron / 2),
        ]
    ):
        spec.worldbody.add_geom(
            name=f"apron{i}",
            type=mujoco.mjtGeom.mjGEOM_BOX,
            size=[hx, hy, depth / 2],
            pos=[cx, cy, -depth / 2],
            rgba=rgba,
            **collide,
        )


def standing_base_height(spec_model: mujoco.MjModel, joint_pos: np.ndarray) -> float:
    """Base height at which the lowest foot collider just touches z = 0 in this pose."""
    data = mujoco.MjData(spec_model)
    data.qpos[:3] = [0.0, 0.0, 1.0]
    data.qpos[3:7] = [1.0, 0.0, 0.0, 0.0]
    data.qpos[7:] = joint_pos
    mujoco.mj_kinematics(spec_model, data)
    lowest = np.inf
    for gid in range(spec_model.ngeom):
        name = mujoco.mj_id2name(spec_model, mujoco.mjtObj.mjOBJ_GEOM, gid) or ""
        if "_foot_sphere" in name:
            lowest = min(lowest, data.geom_xpos[gid, 2] - spec_model.geom_size[gid, 0])
    return 1.0 - lowest


def build_scene(
    cfg: DictConfig,
    terrain: Terrain | None = None,
    decorate: Callable[[mujoco.MjSpec], None] | None = None,
    apron: float | None = None,
) -> Scene:
    """The compiled model for a composed config: G1 + terrain + physics options + `home`.
    `decorate(spec)` may add task objects (bodies, joints) before compilation. `apron`: flat
    ground around the heightfield (default: the config's around a generated grid, none around
    a given terrain)."""
    robot_cfg: RobotConfig = cfg.robot
    spec = g1.build_robot_spec(robot_cfg)
    apply_sim_options(spec, cfg.sim)
    joint_names = [j.name for j in spec.joints if j.type == mujoco.mjtJoint.mjJNT_HINGE]
    home_joints = g1.home_joint_positions(robot_cfg, joint_names)
    base_height = robot_cfg.home_base_height or standing_base_height(spec.compile(), home_joints)

    generated = terrain is None
    terrain = generate(cfg.terrain, cfg.difficulty) if generated else terrain
    # a given terrain (a hardware task) is the whole world; a tile grid gets flat ground around
    if apron is None:
        apron = float(cfg.terrain.apron) if generated else 0.0
    add_terrain(
        spec,
        terrain,
        apron=apron,
        plane=generated and cfg.terrain.flat_as_plane and not terrain.heights.any(),
    )
    if decorate is not None:
        decorate(spec)
    x, y = terrain.tiles[0].centre
    ground = float(terrain.height_at(x, y))
    home_qpos = np.concatenate([[x, y, ground + base_height, 1.0, 0.0, 0.0, 0.0], home_joints])
    spec.add_key(name="home", qpos=home_qpos, ctrl=home_joints)
    model = spec.compile()
    return Scene(model, terrain, joint_names, home_qpos, home_joints, base_height)
