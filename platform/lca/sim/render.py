"""Pictures of the simulation without a display: MuJoCo's own renderer on a render model.

`lca` picks a headless OpenGL backend (EGL, else OSMesa) when it is imported, before MuJoCo
chooses one (`lca/__init__.py`); `gl_unavailable()` says why rendering cannot work here.

A batched scene's heightfield covers the whole tile grid at 1 cm (~10^7 samples), which
software OpenGL draws at seconds per frame. A render model holds the same robot and task
objects, so a simulation qpos drives it unchanged, on a window of the terrain around what is
filmed, at `RENDER_RESOLUTION`, with a checkered ground, a sky and a sun (no shadows).
"""

from __future__ import annotations

import dataclasses
import functools
import math
import os
from collections.abc import Callable

import mujoco
import numpy as np
from omegaconf import DictConfig

from lca.sim import robot as g1
from lca.sim.scene import Scene, build_scene
from lca.sim.terrain import Terrain, Tile

WIDTH, HEIGHT = 320, 240  # clip frames
PREVIEW_WIDTH, PREVIEW_HEIGHT = 480, 360  # a terrain close-up
RENDER_RESOLUTION = 0.02  # m per heightfield sample of a render model (physics: 1 cm)
CHECKER = ([0.58, 0.64, 0.72], [0.5, 0.56, 0.64])  # bluish squares: the G1 itself is grey
CHECKER_SQUARE = 0.5  # m
APRON = 20.0  # m of flat ground drawn around a terrain window
SUPERSAMPLE = 2  # frames are drawn this many times larger, then averaged down
ROBOT_GROUP = 2  # the G1's visual meshes (its colliders are group 3, hidden)
MESH_CELL = 0.01  # m: mesh vertices closer than this merge (393k -> 34k triangles)

Decorate = Callable[[mujoco.MjSpec], None]


@functools.cache
def gl_unavailable() -> str | None:
    """None when MuJoCo can render offscreen in this process; otherwise why not."""
    backend = os.environ.get("MUJOCO_GL") or "glfw (MuJoCo's default)"
    xml = "<mujoco><worldbody><geom size='1'/></worldbody></mujoco>"
    try:
        renderer = mujoco.Renderer(mujoco.MjModel.from_xml_string(xml), 8, 8)
        try:
            renderer.render()
        finally:
            renderer.close()
    except Exception as error:  # any failure to make a GL context means: no rendering here
        detail = str(error).splitlines()[0] if str(error) else ""
        hint = ""
        if "MUJOCO_GL" not in os.environ:
            hint = " (headless: set MUJOCO_GL=egl or osmesa, or import lca before mujoco)"
        return f"MUJOCO_GL={backend}: {type(error).__name__} {detail}{hint}".strip()
    return None


def crop(
    terrain: Terrain,
    lo: tuple[float, float],
    hi: tuple[float, float],
    resolution: float = RENDER_RESOLUTION,
) -> Terrain:
    """The samples of `terrain` inside the world box [lo, hi] (clamped to the terrain), every
    k-th one so that their spacing is about `resolution`; each keeps its world position."""
    res = terrain.resolution
    nrow, ncol = terrain.heights.shape
    step = max(1, int(round(resolution / res)))
    ox, oy = terrain.origin

    def span(low: float, high: float, n: int, origin: float) -> tuple[int, int]:
        first = int(np.clip(math.floor((low - origin) / res), 0, n - 1))
        last = int(np.clip(math.ceil((high - origin) / res), 0, n - 1))
        if last - first < step:  # at least two samples, even for a box off the terrain
            last = min(n - 1, first + step)
            first = max(0, last - step)
        return first, last

    c0, c1 = span(lo[0], hi[0], ncol, ox)
    r0, r1 = span(lo[1], hi[1], nrow, oy)
    heights = terrain.heights[r0 : r1 + 1 : step, c0 : c1 + 1 : step].copy()
    origin = (ox + c0 * res, oy + r0 * res)
    box = Terrain(heights, res * step, origin, [])
    (x0, y0), (sx, sy) = origin, box.size
    box.tiles = [
        t for t in terrain.tiles if x0 <= t.centre[0] <= x0 + sx and y0 <= t.centre[1] <= y0 + sy
    ] or [Tile("window", 0, 0, box.centre)]
    return box


def window(terrain: Terrain, lo: tuple[float, float], hi: tuple[float, float]) -> Terrain:
    """What a render model draws of `terrain` around the world box [lo, hi]: a boxes
    terrain's boxes that meet it, a hardware task's strips whole (a few dozen geoms, exact
    edges: software OpenGL draws them 2-3x faster than a heightfield's triangles), otherwise
    the `crop` of its samples."""
    if terrain.strips is not None:
        return terrain
    if terrain.representation == "boxes":
        return dataclasses.replace(terrain, window=(tuple(lo), tuple(hi)))
    return crop(terrain, lo, hi)


def simplify_mesh(vert: np.ndarray, face: np.ndarray, cell: float) -> tuple:
    """Vertex clustering: vertices in one `cell`-sized voxel merge into their mean; faces
    that collapse or repeat go. Returns (vertices, faces)."""
    _, cluster = np.unique(np.floor(vert / cell).astype(np.int64), axis=0, return_inverse=True)
    cluster = cluster.ravel()
    n = int(cluster.max()) + 1
    merged = np.zeros((n, 3))
    np.add.at(merged, cluster, vert)
    merged /= np.bincount(cluster, minlength=n)[:, None]
    f = cluster[face]
    f = f[(f[:, 0] != f[:, 1]) & (f[:, 1] != f[:, 2]) & (f[:, 0] != f[:, 2])]
    _, first = np.unique(np.sort(f, axis=1), axis=0, return_index=True)
    f = f[np.sort(first)]  # keeps each face's winding, hence its normal
    used = np.unique(f)
    index = np.full(n, -1)
    index[used] = np.arange(used.size)
    return merged[used], index[f]


@functools.cache
def _robot_meshes() -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """The G1's visual meshes simplified, in their file's frame: name -> (vertices, faces).
    Software OpenGL spends most of a frame on the 393k triangles of the original meshes."""
    model = mujoco.MjSpec.from_file(str(g1.g1_xml_path())).compile()
    meshes = {}
    for i in range(model.nmesh):
        v0, nv = model.mesh_vertadr[i], model.mesh_vertnum[i]
        f0, nf = model.mesh_faceadr[i], model.mesh_facenum[i]
        vert, face = simplify_mesh(
            model.mesh_vert[v0 : v0 + nv].astype(float), model.mesh_face[f0 : f0 + nf], MESH_CELL
        )
        # the compiler moved the vertices to the mesh's inertial frame: undo that
        rot = np.zeros(9)
        mujoco.mju_quat2Mat(rot, model.mesh_quat[i])
        vert = vert @ rot.reshape(3, 3).T + model.mesh_pos[i]
        meshes[mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_MESH, i)] = (vert, face)
    return meshes


def _simplify_robot(spec: mujoco.MjSpec) -> None:
    simple = _robot_meshes()
    for mesh in list(spec.meshes):
        if mesh.name in simple and tuple(mesh.scale) == (1.0, 1.0, 1.0):
            vert, face = simple[mesh.name]
            name = mesh.name
            # a mesh already loaded from its file keeps that file's normals: replace it whole
            spec.delete(mesh)
            spec.add_mesh(name=name, uservert=vert.ravel().tolist(), userface=face.ravel().tolist())


def _dress(spec: mujoco.MjSpec) -> None:
    """The look of every picture: light robot meshes, checkered ground, gradient sky and a sun
    instead of the G1's spotlight. No shadows: each shadow-casting light doubles a frame's
    cost."""
    _simplify_robot(spec)
    for light in list(spec.lights):
        spec.delete(light)
    spec.visual.headlight.ambient = [0.35, 0.35, 0.35]
    spec.visual.headlight.diffuse = [0.5, 0.5, 0.5]
    spec.visual.headlight.specular = [0.05, 0.05, 0.05]
    spec.add_texture(
        name="lca_sky",
        type=mujoco.mjtTexture.mjTEXTURE_SKYBOX,
        builtin=mujoco.mjtBuiltin.mjBUILTIN_GRADIENT,
        rgb1=[0.55, 0.7, 0.9],
        rgb2=[0.12, 0.18, 0.3],
        width=256,
        height=256,
    )
    spec.add_texture(
        name="lca_checker",
        type=mujoco.mjtTexture.mjTEXTURE_2D,
        builtin=mujoco.mjtBuiltin.mjBUILTIN_CHECKER,
        rgb1=CHECKER[0],
        rgb2=CHECKER[1],
        width=64,
        height=64,
    )
    ground = spec.add_material(
        name="lca_ground", texuniform=True, texrepeat=[0.5 / CHECKER_SQUARE] * 2
    )
    ground.textures[mujoco.mjtTextureRole.mjTEXROLE_RGB] = "lca_checker"
    for geom in spec.geoms:
        if geom.name.startswith(("terrain", "apron")):  # a field, boxes, strips, the floor
            geom.material = "lca_ground"
            geom.rgba = [1.0, 1.0, 1.0, 1.0]
    spec.worldbody.add_light(
        name="lca_sun",
        type=mujoco.mjtLightType.mjLIGHT_DIRECTIONAL,
        pos=[0.0, 0.0, 10.0],
        dir=[0.35, 0.45, -1.0],
        diffuse=[0.55, 0.55, 0.55],
        castshadow=False,
    )


def render_scene(
    cfg: DictConfig, terrain: Terrain, decorate: Decorate | None = None, apron: float = APRON
) -> Scene:
    """A render model: the robot (and the task objects `decorate` adds) of `cfg` on `terrain`,
    usually a `crop` of the simulated one, with `apron` m of flat ground around it."""

    def dress(spec: mujoco.MjSpec) -> None:
        if decorate is not None:
            decorate(spec)
        _dress(spec)

    return build_scene(cfg, terrain=terrain, decorate=dress, apron=apron)


class Camera:
    """Offscreen frames of a render model, from a free camera that `look` aims. Frames are
    drawn at `supersample` times the size and averaged down: smooth edges at half the cost
    of MuJoCo's multisampling in software OpenGL."""

    def __init__(
        self,
        model: mujoco.MjModel,
        width: int = WIDTH,
        height: int = HEIGHT,
        supersample: int = SUPERSAMPLE,
    ):
        self.model = model
        self.data = mujoco.MjData(model)
        self.size = (height, width)
        self.supersample = supersample
        big = (height * supersample, width * supersample)
        model.vis.quality.offsamples = 0
        model.vis.global_.offwidth = max(model.vis.global_.offwidth, big[1])
        model.vis.global_.offheight = max(model.vis.global_.offheight, big[0])
        self.renderer = mujoco.Renderer(model, *big)
        self.camera = mujoco.MjvCamera()
        self.option = mujoco.MjvOption()  # e.g. option.geomgroup[ROBOT_GROUP] = 0 hides the G1

    def look(self, lookat, distance: float, azimuth_deg: float, elevation_deg: float) -> None:
        self.camera.lookat[:] = lookat
        self.camera.distance = distance
        self.camera.azimuth = azimuth_deg
        self.camera.elevation = elevation_deg

    def render(self, qpos: np.ndarray) -> np.ndarray:
        """(height, width, 3) uint8 of the model in configuration `qpos`."""
        if qpos.shape[-1] != self.model.nq:
            raise ValueError(f"qpos has {qpos.shape[-1]} entries, the render model {self.model.nq}")
        self.data.qpos[:] = qpos
        mujoco.mj_forward(self.model, self.data)
        self.renderer.update_scene(self.data, self.camera, self.option)
        image = self.renderer.render()
        k = self.supersample
        if k == 1:
            return image
        # the k x k block means in integers: 10x faster than a float mean over a reshape
        total = np.zeros((*self.size, image.shape[2]), np.uint32)
        for i in range(k):
            for j in range(k):
                total += image[i::k, j::k]
        return ((total + k * k // 2) // (k * k)).astype(image.dtype)

    def close(self) -> None:
        self.renderer.close()


class TrackingCamera(Camera):
    """Follows one robot's base from beside and a little ahead of it."""

    distance = 2.6  # m
    elevation = -16.0  # deg
    side = 110.0  # deg from the robot's heading: 90 is a pure side view

    def frame(self, qpos: np.ndarray, heading: float) -> np.ndarray:
        """The robot in configuration `qpos`, seen for a base heading of `heading` rad."""
        target = np.asarray(qpos[:3], float) - [0.0, 0.0, 0.15]
        self.look(target, self.distance, math.degrees(heading) + self.side, self.elevation)
        return self.render(qpos)


def close_up(
    cfg: DictConfig,
    terrain: Terrain,
    decorate: Decorate | None = None,
    width: int = PREVIEW_WIDTH,
    height: int = PREVIEW_HEIGHT,
) -> np.ndarray:
    """(height, width, 3) uint8: the robot in its `home` pose on the first tile of `terrain`
    and the ground 6 m around it, seen from above at an angle."""
    x, y = terrain.tiles[0].centre
    near = crop(terrain, (x - 6.0, y - 6.0), (x + 6.0, y + 6.0))
    near.tiles = [Tile(terrain.tiles[0].kind, 0, 0, (x, y))]  # home on the first tile
    scene = render_scene(cfg, near, decorate)
    camera = Camera(scene.model, width, height)
    try:
        camera.look(scene.home_qpos[:3] - [0.0, 0.0, 0.3], 5.5, 45.0, -30.0)
        return camera.render(scene.home_qpos)
    finally:
        camera.close()
