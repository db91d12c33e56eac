"""Headless pictures (lca.sim.render, lca.sim.preview): terrain windows that keep world
positions, light robot meshes that stay in place, a G1 that shows up in a frame, and terrain
previews through `python -m lca.scene preview=`. Tests that draw skip, saying why, where
MuJoCo cannot render."""

from __future__ import annotations

from pathlib import Path

import matplotlib.image
import mujoco
import numpy as np
import pytest
from _cli import run_module

from lca.sim import relief, render
from lca.sim.terrain import Terrain

REPO = Path(__file__).resolve().parents[2]


def needs_gl() -> None:
    reason = render.gl_unavailable()
    if reason:
        pytest.skip(f"MuJoCo cannot render here: {reason}")


def test_crop_keeps_world_positions(mixed_scene) -> None:
    terrain = mixed_scene.terrain
    x, y = terrain.tiles[0].centre
    lo, hi = (x - 1.3, y - 0.7), (x + 2.1, y + 1.9)
    window = render.crop(terrain, lo, hi, resolution=0.02)
    step = 2
    assert window.resolution == pytest.approx(step * terrain.resolution)
    c0 = round((window.origin[0] - terrain.origin[0]) / terrain.resolution)
    r0 = round((window.origin[1] - terrain.origin[1]) / terrain.resolution)
    rows, cols = window.heights.shape
    expected = terrain.heights[r0 : r0 + step * rows : step, c0 : c0 + step * cols : step]
    np.testing.assert_array_equal(window.heights, expected)
    assert window.heights.std() > 0  # the first tile of the mixed grid is not flat here
    (wx, wy), (sx, sy) = window.origin, window.size
    assert wx <= lo[0] and wy <= lo[1]
    assert wx + sx >= hi[0] - window.resolution and wy + sy >= hi[1] - window.resolution
    assert window.tiles[0].centre == (x, y)  # the scene's home stays on the first tile
    away = render.crop(terrain, (1e3, 1e3), (1e3 + 1, 1e3 + 1))  # off the grid: still a field
    assert min(away.heights.shape) >= 2


def test_window_keeps_the_boxes_it_meets(mixed_cfg, mixed_scene) -> None:
    """A boxes terrain's render window: its boxes that meet the window, as the physics has
    them; a hardware ground's strips whole."""
    terrain = mixed_scene.terrain
    assert terrain.representation == "boxes"
    x, y = terrain.tiles[0].centre
    lo, hi = (x - 1.5, y - 2.0), (x + 2.5, y + 1.0)
    near = render.window(terrain, lo, hi)
    assert near.window == (lo, hi) and terrain.window is None  # the physics' terrain untouched
    every, kept = relief.terrain_boxes(terrain), relief.terrain_boxes(near)
    assert 0 < len(kept) < len(every) / 2
    for box in every:
        meets = box.x[1] >= lo[0] and box.x[0] <= hi[0] and box.y[1] >= lo[1] and box.y[0] <= hi[1]
        assert (box in kept) == meets
    model = render.render_scene(mixed_cfg, near).model
    names = [model.geom(i).name for i in range(model.ngeom)]
    assert sum(n.startswith("terrain_box") for n in names) == len(kept)
    strips = Terrain(terrain.heights, terrain.resolution, terrain.origin, terrain.tiles)
    strips.strips = object()  # only its presence matters here
    assert render.window(strips, lo, hi) is strips


def test_supersampled_frame_is_the_block_mean(flat_cfg, flat_scene) -> None:
    """A frame drawn at twice the size comes back as the rounded means of its 2 x 2 blocks."""
    needs_gl()
    x, y = flat_scene.terrain.tiles[0].centre
    scene = render.render_scene(
        flat_cfg, render.crop(flat_scene.terrain, (x - 3, y - 3), (x + 3, y + 3))
    )
    small = render.TrackingCamera(scene.model)
    big = render.TrackingCamera(scene.model, 2 * render.WIDTH, 2 * render.HEIGHT, supersample=1)
    try:
        frame, raw = small.frame(scene.home_qpos, 0.4), big.frame(scene.home_qpos, 0.4)
    finally:
        small.close()
        big.close()
    h, w = frame.shape[:2]
    mean = raw.reshape(h, 2, w, 2, 3).mean(axis=(1, 3))
    assert np.abs(frame - mean).max() <= 0.5 + 1e-9
    assert frame.std() > 10


def test_simplified_meshes_stay_in_place(flat_cfg, flat_scene) -> None:
    vert = flat_scene.model.mesh_vert
    face = flat_scene.model.mesh_face
    i = int(np.argmax(flat_scene.model.mesh_facenum))  # the largest mesh
    v0, nv = flat_scene.model.mesh_vertadr[i], flat_scene.model.mesh_vertnum[i]
    f0, nf = flat_scene.model.mesh_faceadr[i], flat_scene.model.mesh_facenum[i]
    v, f = render.simplify_mesh(vert[v0 : v0 + nv].astype(float), face[f0 : f0 + nf], 0.01)
    assert len(f) < nf / 3
    assert f.min() >= 0 and f.max() < len(v)
    original = vert[v0 : v0 + nv]
    np.testing.assert_allclose(v.min(0), original.min(0), atol=0.01)
    np.testing.assert_allclose(v.max(0), original.max(0), atol=0.01)

    x, y = flat_scene.terrain.tiles[0].centre
    window = render.crop(flat_scene.terrain, (x - 2, y - 2), (x + 2, y + 2))
    model = render.render_scene(flat_cfg, window).model
    assert model.nq == flat_scene.model.nq  # a simulation qpos drives the render model
    assert model.nmeshface < flat_scene.model.nmeshface / 5
    poses = []
    for m in (flat_scene.model, model):
        d = mujoco.MjData(m)
        d.qpos[:] = flat_scene.home_qpos
        mujoco.mj_kinematics(m, d)
        meshes = m.geom_type == mujoco.mjtGeom.mjGEOM_MESH
        poses.append(d.geom_xpos[meshes])
    # every visual mesh where the simulated robot has it (moved by at most its re-centring)
    assert poses[0].shape == poses[1].shape and len(poses[0]) > 20
    assert np.abs(poses[0] - poses[1]).max() < 0.005


def _neutral(image: np.ndarray) -> np.ndarray:
    """Grey pixels: the G1's materials are grey and black; ground and sky are bluish."""
    return (image.max(axis=2).astype(int) - image.min(axis=2)) < 12


def test_g1_standing_on_flat_ground_is_in_the_frame(flat_cfg, flat_scene) -> None:
    needs_gl()
    x, y = flat_scene.terrain.tiles[0].centre
    window = render.crop(flat_scene.terrain, (x - 3, y - 3), (x + 3, y + 3))
    scene = render.render_scene(flat_cfg, window)
    qpos = flat_scene.home_qpos
    camera = render.TrackingCamera(scene.model)
    plain = render.TrackingCamera(scene.model, supersample=1)
    try:
        frame = camera.frame(qpos, 0.4)
        plain.renderer.enable_segmentation_rendering()
        ids = plain.frame(qpos, 0.4)
        camera.option.geomgroup[render.ROBOT_GROUP] = 0
        empty = camera.frame(qpos, 0.4)
    finally:
        camera.close()
        plain.close()
    assert frame.shape == (render.HEIGHT, render.WIDTH, 3) and frame.dtype == np.uint8
    assert frame.std() > 10 and empty.std() > 3  # ground, sky and robot; not a blank frame
    body = scene.model.geom_bodyid[np.clip(ids[..., 0], 0, None)]
    robot = (ids[..., 1] == mujoco.mjtObj.mjOBJ_GEOM) & (ids[..., 0] >= 0) & (body > 0)
    h, w = robot.shape
    centre = (slice(h // 4, 3 * h // 4), slice(w // 4, 3 * w // 4))
    assert robot[centre].mean() > 0.05  # the robot fills part of the image centre
    grey = _neutral(frame)
    assert grey[centre].mean() > 0.05  # ... in its own colours
    assert grey[robot].mean() > 0.8
    assert _neutral(empty)[centre].mean() < 0.005  # the empty scene has none of them
    change = np.abs(frame.astype(int) - empty).max(axis=2)
    assert change[robot].mean() > 30  # the robot is what differs from the empty scene
    assert (change[~robot] > 30).mean() < 0.03  # (its outline aside)


@pytest.mark.slow  # a subprocess that builds the scene and renders
def test_scene_preview_cli(tmp_path: Path) -> None:
    """`python -m lca.scene terrain=stairs_up difficulty=hard scale=smoke preview=...`."""
    png = tmp_path / "terrain.png"
    args = ["terrain=stairs_up", "difficulty=hard", "scale=smoke", f"preview={png}"]
    out = run_module("lca.scene", *args, cwd=tmp_path, timeout=180)
    assert out.returncode == 0, out.stderr[-3000:]
    assert f"wrote {png}" in out.stdout
    image = matplotlib.image.imread(png)
    assert image.shape[:2] == (420, 1100)
    left, right = image[:, :500, :3], image[:, 600:, :3]
    assert left.std() > 0.1  # the height map
    if render.gl_unavailable() is None:
        assert right.std() > 0.05  # the rendered close-up
    usage = run_module("lca.scene", "scale=smoke", cwd=tmp_path)
    assert usage.returncode == 2 and "preview=PATH.png" in usage.stderr
