"""The four hardware tasks as MuJoCo scenes (paper, "Hardware Experiments"): stair geometry
(3 steps, 18 cm risers, 20 cm landings, 25 degree skew), 36 cm ledges, a hinged plank that
tips under load, and a soft mat that gives more than rigid ground."""

from __future__ import annotations

import functools

import mujoco
import numpy as np
import pytest

from lca.config import compose
from lca.sim.hardware import TASKS, build_task
from lca.sim.scene import build_scene

TERRAIN_ONLY = np.array([1, 1, 0, 0, 0, 0], dtype=np.uint8)  # robot geoms are groups 2-4


@pytest.fixture(scope="module")
def cfg():
    return compose(["scale=smoke"])


@pytest.fixture(scope="module")
def built(cfg):
    return functools.cache(lambda name: build_task(cfg, name))


def ray_heights(model: mujoco.MjModel, x, y) -> np.ndarray:
    """Top surface height of the static/task geometry under (x, y), by MuJoCo ray casts."""
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    top = 5.0
    out = []
    for px, py in zip(np.ravel(x), np.ravel(y), strict=True):
        dist = mujoco.mj_ray(
            model,
            data,
            np.array([px, py, top]),
            np.array([0.0, 0.0, -1.0]),
            TERRAIN_ONLY,
            1,
            -1,
            np.zeros(1, np.int32),
        )
        assert dist >= 0, (px, py)
        out.append(top - dist)
    return np.array(out)


def edges_along(terrain, start, direction, length, levels, step=1e-3) -> list[float]:
    """Distances along a line at which the surface crosses each of `levels`."""
    t = np.arange(0.0, length, step)
    x, y = start[0] + t * direction[0], start[1] + t * direction[1]
    h = terrain.height_at(x, y)
    found = []
    for level in levels:
        above = h >= level
        crossings = np.flatnonzero(above[1:] != above[:-1])
        assert crossings.size == 1, (level, crossings)
        i = crossings[0]
        found.append(t[i] + step * (level - h[i]) / (h[i + 1] - h[i]))
    return found


# ---- stairs -----------------------------------------------------------------------------


@pytest.mark.parametrize("name", ["stair_ascent", "stair_descent"])
def test_stairs_three_equal_risers_along_the_walking_direction(cfg, built, name):
    task, scene = built(name)
    st = cfg.hardware.stairs
    res = task.terrain.resolution
    row = int(round((0.0 - task.terrain.origin[1]) / res))  # y = 0, the robot's path
    profile = task.terrain.heights[row]
    steps = np.diff(profile)
    jumps = steps[steps != 0]
    assert jumps.size == st.steps == 3
    np.testing.assert_allclose(np.abs(jumps), st.riser, atol=1e-12)
    assert st.riser == pytest.approx(0.18)
    top = st.steps * st.riser
    start = float(task.terrain.height_at(0.0, 0.0))
    end = float(task.terrain.height_at(task.goal_x, 0.0))
    if name == "stair_ascent":
        assert (steps >= 0).all() and (start, end) == pytest.approx((0.0, top))
    else:
        assert (steps <= 0).all() and (start, end) == pytest.approx((top, 0.0))
    # The robot starts at the origin facing +x, standing on the ground there.
    np.testing.assert_allclose(scene.home_qpos[:2], 0.0)
    np.testing.assert_allclose(scene.home_qpos[3:7], [1, 0, 0, 0])
    assert scene.home_qpos[2] == pytest.approx(start + scene.base_height)
    # The goal line is past the top step for every lateral position of the path.
    assert task.goal_x > (cfg.hardware.approach + top) / np.cos(np.radians(st.skew_deg))


@pytest.mark.parametrize("name", ["stair_ascent", "stair_descent"])
def test_stair_landings_are_20_cm_along_the_skewed_direction(cfg, built, name):
    task, _ = built(name)
    hw = cfg.hardware
    st = hw.stairs
    s = np.radians(st.skew_deg)
    along, across = np.array([np.cos(s), np.sin(s)]), np.array([-np.sin(s), np.cos(s)])
    levels = (np.arange(st.steps) + 0.5) * st.riser
    depths, firsts = [], []
    for u in np.linspace(-0.6, 0.6, 7):
        edges = edges_along(task.terrain, u * across, along, 2.5, levels)
        if name == "stair_descent":
            edges = edges[::-1]  # the top level is crossed first when walking down
        firsts.append(edges[0])
        depths += list(np.diff(edges))
    depths = np.array(depths)
    assert np.abs(depths - st.landing).max() < 0.015  # 1 cm heightfield samples
    assert depths.mean() == pytest.approx(0.20, abs=0.003)
    assert np.mean(firsts) == pytest.approx(hw.approach, abs=0.005)


@pytest.mark.parametrize("name", ["stair_ascent", "stair_descent"])
def test_stair_edges_are_skewed_25_degrees(cfg, built, name):
    """Edges are lines x cos(s) + y sin(s) = const, so x_edge(y) has slope dx/dy = -tan(s)."""
    task, _ = built(name)
    st = cfg.hardware.stairs
    terrain = task.terrain
    res = terrain.resolution
    ncol = terrain.heights.shape[1]
    xs = terrain.origin[0] + res * np.arange(ncol)
    ys = terrain.origin[1] + res * np.arange(terrain.heights.shape[0])
    rows = np.flatnonzero(np.abs(ys) <= 1.5)
    for k in range(1, st.steps + 1):
        level = k * st.riser if name == "stair_ascent" else (st.steps - k) * st.riser
        x_edge = []
        for r in rows:
            h = terrain.heights[r]
            hit = h >= level - st.riser / 2 if name == "stair_ascent" else h <= level + st.riser / 2
            first = int(np.argmax(hit))
            x_edge.append(xs[first] - res / 2)
        slope, intercept = np.polyfit(ys[rows], x_edge, 1)
        skew = np.degrees(np.arctan(-slope))
        assert skew == pytest.approx(25.0, abs=0.5)
        # ...and the k-th edge crosses y = 0 at (approach + (k-1) landing) / cos(s).
        s = np.radians(st.skew_deg)
        assert intercept == pytest.approx(
            (cfg.hardware.approach + (k - 1) * st.landing) / np.cos(s), abs=0.01
        )


ALL_TASKS = ["stair_ascent", "stair_descent", "hinged_ledge", "soft_ledge"]


@functools.cache
def built_as(representation: str, name: str):
    return build_task(compose(["scale=smoke", f"hardware.representation={representation}"]), name)


@pytest.mark.parametrize("representation", ["strips", "heightfield"])
@pytest.mark.parametrize("name", ALL_TASKS)
def test_mujoco_ground_is_the_task_terrain(representation, name):
    """What the robot and the cameras collide with is what the task layer queries, in
    either representation of the static ground (the task objects are not ground: the
    points sample the ground before them and beside them)."""
    task, scene = built_as(representation, name)
    rng = np.random.default_rng(5)
    x, y = rng.uniform(-1.0, 3.0, 150), rng.uniform(-1.0, 1.0, 150)
    if "ledge" in name:
        x = np.where(np.abs(y) < 0.6, np.minimum(x, 0.9), x)  # off the plank and the mat
    np.testing.assert_allclose(
        ray_heights(scene.model, x, y), task.terrain.height_at(x, y), atol=1e-4
    )


def slanted_rays(model: mujoco.MjModel, origins, vectors) -> np.ndarray:
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    geomid = np.zeros(1, np.int32)
    return np.array(
        [
            mujoco.mj_ray(model, data, p, v, TERRAIN_ONLY, 1, -1, geomid)
            for p, v in zip(origins, vectors, strict=True)
        ]
    )


def marched(terrain, origins, vectors, step: float = 1e-4) -> np.ndarray:
    """Distance along each ray to its first point at or below `terrain.height_at`."""
    t = np.arange(0.0, 3.0, step)
    out = []
    for p, v in zip(origins, vectors, strict=True):
        points = p + t[:, None] * v
        below = points[:, 2] <= terrain.height_at(points[:, 0], points[:, 1])
        out.append(t[np.argmax(below)])
    return np.array(out)


@pytest.mark.parametrize("name", ["stair_ascent", "hinged_ledge"])
def test_strips_show_the_cameras_the_exact_ground(name):
    """Camera-like rays (pitched 50-80 degrees down, any heading, from 1.2 m over the path)
    hit the strips where they first meet the task's step function; the heightfield, whose
    skewed risers are 1 cm ramps, agrees except for rays grazing a riser."""
    rng = np.random.default_rng(7)
    n = 300
    origins = np.stack([rng.uniform(-0.5, 3.0, n), rng.uniform(-0.5, 0.5, n), np.full(n, 1.2)], 1)
    pitch, heading = np.radians(rng.uniform(50, 80, n)), rng.uniform(-np.pi, np.pi, n)
    vectors = np.stack(
        [np.cos(pitch) * np.cos(heading), np.cos(pitch) * np.sin(heading), -np.sin(pitch)], 1
    )
    if name == "hinged_ledge":  # rays that reach the plank are the plank's, not the ground's
        origins[:, 0] = np.minimum(origins[:, 0], 0.5)
        vectors[:, 0] = -np.abs(vectors[:, 0])
    task, scene = built_as("strips", name)
    strips = slanted_rays(scene.model, origins, vectors)
    np.testing.assert_allclose(strips, marched(task.terrain, origins, vectors), atol=2e-4)
    field = slanted_rays(built_as("heightfield", name)[1].model, origins, vectors)
    assert np.mean(np.abs(strips - field) < 0.02) >= 0.95


# ---- ledges -----------------------------------------------------------------------------


def plank_top_when_level(model: mujoco.MjModel) -> float:
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    gid = model.geom("plank").id
    return float(data.geom_xpos[gid, 2] + model.geom_size[gid, 2])


def test_hinged_ledge_platform_is_36_cm_above_the_plank(cfg, built):
    task, scene = built("hinged_ledge")
    hw, p = cfg.hardware, cfg.hardware.plank
    model = scene.model
    plank_top = plank_top_when_level(model)
    assert plank_top == pytest.approx(p.pivot_height + p.thickness / 2)
    platform = ray_heights(model, [0.3, 0.8], [0.0, 0.2])
    on_plank = ray_heights(model, [hw.approach + 0.2, hw.approach + p.length - 0.2], [0.1, -0.1])
    np.testing.assert_allclose(platform, task.terrain.height_at([0.3, 0.8], [0.0, 0.2]))
    np.testing.assert_allclose(platform - plank_top, hw.ledge_drop, atol=1e-4)
    np.testing.assert_allclose(on_plank, plank_top, atol=1e-6)
    assert hw.ledge_drop == pytest.approx(0.36)
    # The plank spans [approach + gap, approach + gap + length]; the goal is past its end.
    gid = model.geom("plank").id
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    assert data.geom_xpos[gid, 0] - model.geom_size[gid, 0] == pytest.approx(hw.approach + p.gap)
    assert task.goal_x > hw.approach + p.gap + p.length


def test_hinge_is_a_balanced_pivot_with_the_configured_range(cfg, built):
    _, scene = built("hinged_ledge")
    p = cfg.hardware.plank
    model = scene.model
    jid = model.joint("plank_hinge").id
    assert model.jnt_type[jid] == mujoco.mjtJoint.mjJNT_HINGE
    assert model.jnt_limited[jid]
    np.testing.assert_allclose(model.jnt_range[jid], np.radians([-p.tip_deg, p.tip_deg]))
    np.testing.assert_allclose(model.jnt_axis[jid], [0, 1, 0])
    assert model.dof_damping[model.jnt_dofadr[jid]] == pytest.approx(p.damping)
    body = model.jnt_bodyid[jid]
    assert model.body(body).name == "plank"
    assert model.body_mass[body] == pytest.approx(p.mass)
    np.testing.assert_allclose(model.body_ipos[body], 0.0, atol=1e-9)  # CoM on the axis


def test_soft_ledge_platform_is_36_cm_above_the_mat(cfg, built):
    task, scene = built("soft_ledge")
    hw, m = cfg.hardware, cfg.hardware.mat
    model = scene.model
    gid = model.geom("soft_mat").id
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    mat_top = data.geom_xpos[gid, 2] + model.geom_size[gid, 2]
    assert mat_top == pytest.approx(m.thickness)
    platform = ray_heights(model, [0.2, 0.7], [0.0, -0.3])
    on_mat = ray_heights(model, [hw.approach + 0.3, hw.approach + m.length - 0.3], [0.0, 0.2])
    np.testing.assert_allclose(platform - mat_top, hw.ledge_drop, atol=1e-4)
    np.testing.assert_allclose(on_mat, mat_top, atol=1e-6)
    np.testing.assert_allclose(model.geom_solref[gid], m.solref)
    np.testing.assert_allclose(model.geom_solimp[gid], m.solimp)
    assert model.geom_priority[gid] > 0


# ---- physics ----------------------------------------------------------------------------


def add_load(spec: mujoco.MjSpec, name: str, pos, kind: str, half: float, mass: float) -> None:
    """A free body colliding with terrain and task objects, like the robot's colliders."""
    body = spec.worldbody.add_body(name=name, pos=list(pos))
    body.add_freejoint(name=name)
    geom_type = mujoco.mjtGeom.mjGEOM_BOX if kind == "box" else mujoco.mjtGeom.mjGEOM_SPHERE
    body.add_geom(
        name=name, type=geom_type, size=[half] * 3, mass=mass, contype=2, conaffinity=1, condim=3
    )


def scene_with(cfg, name: str, extra) -> tuple[mujoco.MjModel, mujoco.MjData]:
    """The task's scene plus extra bodies; the robot stands 1 m behind the start, out of
    the way, under its home PD targets."""
    task = TASKS[name](cfg.hardware)

    def decorate(spec: mujoco.MjSpec) -> None:
        task.decorate(spec)
        extra(spec)

    scene = build_scene(cfg, terrain=task.terrain, decorate=decorate)
    model = scene.model
    data = mujoco.MjData(model)
    mujoco.mj_resetData(model, data)  # qpos0: the extra bodies where they were added
    data.qpos[: scene.home_qpos.size] = scene.home_qpos
    data.qpos[0] = -1.0
    data.ctrl[:] = scene.home_joint_pos
    return model, data


def plank_run(cfg, end: int, seconds: float = 1.5):
    """Hinge angle trajectory with a 20 kg box dropped near one end of the plank
    (+1: the far end, -1: the end under the ledge, 0: no load) and the final data."""
    hw, p = cfg.hardware, cfg.hardware.plank
    centre = hw.approach + p.gap + p.length / 2
    top = p.pivot_height + p.thickness / 2

    def extra(spec: mujoco.MjSpec) -> None:
        if end:
            add_load(
                spec,
                "load",
                [centre + end * (p.length / 2 - 0.1), 0, top + 0.085],
                "box",
                0.08,
                20.0,
            )

    model, data = scene_with(cfg, "hinged_ledge", extra)
    adr = model.jnt_qposadr[model.joint("plank_hinge").id]
    angles = []
    for _ in range(int(round(seconds / model.opt.timestep))):
        mujoco.mj_step(model, data)
        angles.append(data.qpos[adr])
    return np.array(angles), model, data


@pytest.fixture(scope="module")
def plank_runs(cfg):
    return {end: plank_run(cfg, end) for end in (1, -1, 0)}


@pytest.mark.parametrize("end", [1, -1])
def test_hinged_plank_tips_towards_the_loaded_end(cfg, plank_runs, end):
    angles, _, _ = plank_runs[end]
    tip = np.radians(cfg.hardware.plank.tip_deg)
    # Positive rotation about +y lowers the +x (far) end.
    assert np.sign(angles[-1]) == end
    assert abs(angles[-1]) > 0.5 * tip  # tipped well over, towards the limit
    assert np.abs(angles).max() <= tip + np.radians(1.5)  # the limit holds (soft, on impact)
    assert abs(angles[-1]) <= tip + np.radians(0.25)  # ...and at rest
    assert np.all(np.sign(angles[np.abs(angles) > 1e-6]) == end)  # never the other way


def test_unloaded_plank_stays_level(plank_runs):
    angles, _, _ = plank_runs[0]
    assert np.abs(angles).max() < 1e-6


@pytest.mark.parametrize("end", [1, -1])
def test_loaded_plank_does_not_sink_into_the_ground(plank_runs, end):
    _, model, data = plank_runs[end]
    gid = model.geom("plank").id
    size = model.geom_size[gid]
    corners = np.array([[a, b, c] for a in (-1, 1) for b in (-1, 1) for c in (-1, 1)]) * size
    world = data.geom_xpos[gid] + corners @ data.geom_xmat[gid].reshape(3, 3).T
    assert world[:, 2].min() >= -0.005  # the ground is at z = 0 under the plank


def test_soft_mat_gives_much_more_than_rigid_ground(cfg):
    """Two identical foot-like spheres rest on the mat and on the rigid ground past it; the
    mat's config solref/solimp (priority over the load's defaults) let the first sink."""
    hw, m = cfg.hardware, cfg.hardware.mat
    r = 0.06
    on_mat_xy = (hw.approach + m.length / 2, 0.0)
    on_ground_xy = (hw.approach + m.length + 1.0, 0.0)

    def extra(spec: mujoco.MjSpec) -> None:
        add_load(spec, "on_mat", [*on_mat_xy, m.thickness + r + 0.002], "sphere", r, 10.0)
        add_load(spec, "on_ground", [*on_ground_xy, r + 0.002], "sphere", r, 10.0)

    model, data = scene_with(cfg, "soft_ledge", extra)
    mat_adr = model.jnt_qposadr[model.joint("on_mat").id]
    ground_adr = model.jnt_qposadr[model.joint("on_ground").id]
    for _ in range(int(round(1.5 / model.opt.timestep))):
        mujoco.mj_step(model, data)
    mat_sink = m.thickness - (data.qpos[mat_adr + 2] - r)
    ground_sink = 0.0 - (data.qpos[ground_adr + 2] - r)
    np.testing.assert_allclose(data.qpos[mat_adr : mat_adr + 2], on_mat_xy, atol=0.01)
    np.testing.assert_allclose(data.qpos[ground_adr : ground_adr + 2], on_ground_xy, atol=0.01)
    mat_dof = model.jnt_dofadr[model.joint("on_mat").id]
    assert np.abs(data.qvel[mat_dof : mat_dof + 3]).max() < 0.01  # at rest
    assert 0.005 < mat_sink < m.thickness  # sinks centimetres, does not go through
    assert 0 <= ground_sink < 0.002
    assert mat_sink > 10 * ground_sink
    # The contact with the mat uses the mat's parameters.
    mat_gid, load_gid = model.geom("soft_mat").id, model.geom("on_mat").id
    contacts = [
        data.contact[i]
        for i in range(data.ncon)
        if {data.contact[i].geom1, data.contact[i].geom2} == {mat_gid, load_gid}
    ]
    assert contacts
    np.testing.assert_allclose(contacts[0].solref, m.solref)
    np.testing.assert_allclose(contacts[0].solimp, m.solimp)


# ---- python -m lca.hardware.scenes -------------------------------------------------------


@pytest.mark.slow  # a stage's command
def test_scenes_command_writes_each_task_as_a_loadable_model(tmp_path, capsys) -> None:
    from lca.hardware import scenes

    assert scenes.main(["scale=smoke", f"out={tmp_path}"]) == 0
    written = sorted(p.stem for p in tmp_path.glob("*.mjb"))
    assert written == sorted(TASKS)
    assert capsys.readouterr().out.count("wrote ") == len(TASKS)
    robot = build_scene(compose(["scale=smoke"])).model
    for name in TASKS:
        model = mujoco.MjModel.from_binary_path(str(tmp_path / f"{name}.mjb"))
        assert model.nu == robot.nu  # the G1's actuators, unchanged
        assert model.nkey >= 1  # starts from `home`
        # the task geometry is there: the hinged ledge adds its plank's hinge
        assert (model.njnt > robot.njnt) == (name == "hinged_ledge"), name
        data = mujoco.MjData(model)
        mujoco.mj_resetDataKeyframe(model, data, 0)
        mujoco.mj_step(model, data)
        assert np.isfinite(data.qpos).all()
