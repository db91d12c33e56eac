"""The compiled scene: actuators, the heightfield as MuJoCo sees it, and a passive stand."""

from __future__ import annotations

import copy
import math
import re

import mujoco
import numpy as np
import pytest

from lca.sim.batch import BatchedSim
from lca.sim.scene import Scene, build_scene


def _group_of(cfg, joint: str) -> str:
    groups = [
        name
        for name, group in cfg.robot.actuators.items()
        if any(re.fullmatch(p, joint) for p in group.joints)
    ]
    assert len(groups) == 1, f"{joint} matches {groups}"
    return groups[0]


def _reflected_inertia(group) -> float:
    """Rotor inertia seen at the joint, times motors (independent of lca.sim.robot)."""
    ratios = list(group.gear_ratio)
    return group.motors * sum(
        inertia * math.prod(ratios[i + 1 :]) ** 2 for i, inertia in enumerate(group.rotor_inertia)
    )


@pytest.fixture(scope="module")
def field_scene(mixed_cfg) -> Scene:
    """The mixed smoke terrain as one heightfield (terrain.representation=heightfield)."""
    cfg = copy.deepcopy(mixed_cfg)
    cfg.terrain.representation = "heightfield"
    return build_scene(cfg)


def test_scene_structure(field_scene: Scene) -> None:
    mixed_scene = field_scene
    model = mixed_scene.model
    assert model.nu == 29 and len(mixed_scene.joint_names) == 29
    terrain_geom = model.geom("terrain")
    assert terrain_geom.type[0] == mujoco.mjtGeom.mjGEOM_HFIELD
    nrow, ncol = mixed_scene.terrain.heights.shape
    assert (model.hfield_nrow[0], model.hfield_ncol[0]) == (nrow, ncol)
    key = model.key("home")
    assert mixed_scene.home_key == key.id
    np.testing.assert_array_equal(key.qpos, mixed_scene.home_qpos)
    np.testing.assert_array_equal(key.ctrl, mixed_scene.home_joint_pos)


def test_actuators_pd_gains_and_limits(flat_cfg, flat_scene: Scene) -> None:
    model = flat_scene.model
    rc = flat_cfg.robot
    omega = 2 * math.pi * rc.natural_frequency_hz
    assert model.nu == 29
    actuated = set()
    for a in range(model.nu):
        assert model.actuator_trntype[a] == mujoco.mjtTrn.mjTRN_JOINT
        jid = model.actuator_trnid[a, 0]
        joint = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, jid)
        actuated.add(joint)
        group = rc.actuators[_group_of(flat_cfg, joint)]
        armature = model.dof_armature[model.jnt_dofadr[jid]]
        assert armature > 0
        np.testing.assert_allclose(armature, _reflected_inertia(group), rtol=1e-9, err_msg=joint)
        kp = armature * omega**2
        kd = 2 * rc.damping_ratio * armature * omega
        # Position servo: force = kp * ctrl - kp * q - kd * qdot.
        np.testing.assert_allclose(model.actuator_gainprm[a, 0], kp, rtol=1e-9, err_msg=joint)
        np.testing.assert_allclose(model.actuator_biasprm[a, :3], [0, -kp, -kd], rtol=1e-9)
        limit = group.effort_limit
        assert model.actuator_forcelimited[a]
        np.testing.assert_array_equal(model.actuator_forcerange[a], [-limit, limit])
        assert model.jnt_actfrclimited[jid]
        np.testing.assert_array_equal(model.jnt_actfrcrange[jid], [-limit, limit])
    assert actuated == set(flat_scene.joint_names)


def test_heightfield_matches_height_at_by_raycast(field_scene: Scene) -> None:
    mixed_scene = field_scene
    model, terrain = mixed_scene.model, mixed_scene.terrain
    data = mujoco.MjData(model)
    data.qpos[:] = mixed_scene.home_qpos
    data.qpos[2] = 100.0  # lift the robot out of the way of the rays
    mujoco.mj_forward(model, data)
    terrain_id = model.geom("terrain").id
    h, res = terrain.heights, terrain.resolution
    ox, oy = terrain.origin
    rng = np.random.default_rng(0)
    # 200 uniform points, plus points in cells whose corners are not coplanar (corners of
    # steps and blocks), where the choice of triangulation diagonal matters.
    sx, sy = terrain.size
    x = ox + rng.uniform(0, sx, 200)
    y = oy + rng.uniform(0, sy, 200)
    bent = np.argwhere(np.abs(h[:-1, :-1] + h[1:, 1:] - h[:-1, 1:] - h[1:, :-1]) > 1e-3)
    assert len(bent) > 50
    rc = bent[rng.choice(len(bent), min(len(bent), 200), replace=False)]
    x = np.r_[x, ox + (rc[:, 1] + rng.uniform(0, 1, len(rc))) * res]
    y = np.r_[y, oy + (rc[:, 0] + rng.uniform(0, 1, len(rc))) * res]
    top = h.max() + 1.0
    geomid = np.zeros(1, np.int32)
    hit = np.empty(len(x))
    for i, (xi, yi) in enumerate(zip(x, y, strict=True)):
        dist = mujoco.mj_ray(
            model, data, np.array([xi, yi, top]), np.array([0.0, 0.0, -1.0]), None, 1, -1, geomid
        )
        assert geomid[0] == terrain_id, (xi, yi, geomid[0])
        hit[i] = top - dist
    np.testing.assert_allclose(hit, terrain.height_at(x, y), rtol=0, atol=1e-5)


def test_g1_holds_home_under_pd_on_flat(flat_cfg, flat_scene: Scene) -> None:
    # Why robot.natural_frequency_hz=30 (see conftest.STAND_OVERRIDES): a passive stand of a
    # 33 kg humanoid whose CoM is ~0.67 m above the ankles needs ankle stiffness above m*g*h
    # (~220 N m/rad); the 10 Hz training gains (ankle kp 28.5) rely on the policy for balance.
    assert flat_cfg.robot.natural_frequency_hz == 30
    sim = BatchedSim(flat_scene, num_envs=1, num_threads=1)
    sim.reset()
    home_z = flat_scene.home_qpos[2]
    assert sim.qpos[0, 2] == home_z
    for _ in range(20):  # 20 x 50 = 1000 steps = 5 s at 200 Hz
        sim.step(nstep=50)
        assert abs(sim.qpos[0, 2] - home_z) < 0.05, sim.qpos[0, 2] - home_z
        assert sim.sensor("imu_up")[0, 2] > 0.95  # projected gravity z < -0.95
    assert np.isclose(sim.time[0], 1000 * flat_cfg.sim.timestep)
    # Standing on both feet, which carry the whole weight.
    left, right = sim.sensor("left_foot_contact")[0], sim.sensor("right_foot_contact")[0]
    assert left[0] > 0 and right[0] > 0
    weight = flat_scene.model.body_subtreemass[0] * 9.81
    np.testing.assert_allclose(-(left[3] + right[3]), weight, rtol=0.05)
