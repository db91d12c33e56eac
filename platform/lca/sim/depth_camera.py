"""Downward depth cameras simulated by ray casting (no OpenGL), D435-like.

Each camera is fixed to a robot body; a ray grid subsamples the sensor's field of view.
Depth gets stereo-like noise (sigma = k * d^2) and a share of invalid pixels; rays that hit
nothing or fall outside [min_range, max_range] are invalid too. Robot geoms are not seen.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from lca.sim.batch import BatchedSim

# Terrain and task objects live in geom groups 0-1; the robot's are 2 (visual) and 3-4.
SEEN_GROUPS = np.array([1, 1, 0, 0, 0, 0], dtype=np.uint8)


@dataclass
class CameraSpec:
    body: str
    pos: list[float]  # in the body frame (m)
    pitch_deg: float  # optical axis below the body's horizontal (90 = straight down)
    yaw_deg: float = 0.0  # optical axis heading in the body frame (180 = looking back)
    fov_h_deg: float = 87.0  # D435 depth field of view
    fov_v_deg: float = 58.0
    rays_h: int = 24  # ray grid (the D435's 848 x 480 subsampled for CPU speed)
    rays_w: int = 36
    min_range: float = 0.1
    max_range: float = 3.0
    noise_k: float = 0.004  # depth noise sigma = k * d^2 (m)
    invalid_fraction: float = 0.02


def ray_directions(spec: CameraSpec) -> np.ndarray:
    """(R, 3) unit ray directions in the body frame."""
    h = np.tan(np.radians(spec.fov_h_deg) / 2) * np.linspace(-1, 1, spec.rays_w)
    v = np.tan(np.radians(spec.fov_v_deg) / 2) * np.linspace(-1, 1, spec.rays_h)
    hh, vv = np.meshgrid(h, v)
    # camera frame: z forward (optical axis), x right, y down
    cam = np.stack([hh.ravel(), vv.ravel(), np.ones(hh.size)], axis=1)
    cam /= np.linalg.norm(cam, axis=1, keepdims=True)
    # camera -> body: optical axis forward (+x), right = -y, down = -z; then pitch and yaw
    to_body = np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])
    p, y = np.radians(spec.pitch_deg), np.radians(spec.yaw_deg)
    pitch = np.array([[np.cos(p), 0, np.sin(p)], [0, 1, 0], [-np.sin(p), 0, np.cos(p)]])
    yaw = np.array([[np.cos(y), -np.sin(y), 0], [np.sin(y), np.cos(y), 0], [0, 0, 1]])
    return cam @ to_body.T @ pitch.T @ yaw.T


class DepthCameras:
    """All cameras of all environments; `capture()` returns a merged world point cloud."""

    def __init__(self, sim: BatchedSim, specs: list[CameraSpec], rng: np.random.Generator):
        self.sim = sim
        self.specs = specs
        self.rng = rng
        model = sim.model
        self.body_ids = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, s.body) for s in specs]
        self.dirs = [ray_directions(s) for s in specs]
        self.xpos = sim.batch.bind("xpos")
        self.xmat = sim.batch.bind("xmat")
        n, rays = sim.num_envs, sum(len(d) for d in self.dirs)
        self.dist = np.zeros((n, rays))
        self.geomid = np.zeros((n, rays), dtype=np.int32)

    def capture(self) -> tuple[np.ndarray, np.ndarray]:
        """(N, R, 3) world points and (N, R) validity of every ray of every camera."""
        n = self.sim.num_envs
        origins, vectors, limits = [], [], []
        for spec, body, dirs in zip(self.specs, self.body_ids, self.dirs, strict=True):
            rot = self.xmat[:, body].reshape(n, 3, 3)
            origin = self.xpos[:, body] + rot @ np.asarray(spec.pos)
            origins.append(np.repeat(origin[:, None], len(dirs), axis=1))
            vectors.append(np.einsum("nij,rj->nri", rot, dirs))
            limits.append((spec, len(dirs)))
        pnt = np.ascontiguousarray(np.concatenate(origins, axis=1))
        vec = np.ascontiguousarray(np.concatenate(vectors, axis=1))
        self.sim.batch.rays(pnt, vec, self.dist, geomid=self.geomid, geomgroup=SEEN_GROUPS)
        depth = self.dist.copy()
        valid = np.zeros_like(depth, dtype=bool)
        start = 0
        for spec, count in limits:
            part = slice(start, start + count)
            d = depth[:, part]
            ok = (d >= spec.min_range) & (d <= spec.max_range)
            ok &= self.rng.random(d.shape) >= spec.invalid_fraction
            depth[:, part] = d + self.rng.normal(0.0, 1.0, d.shape) * spec.noise_k * d**2
            valid[:, part] = ok
            start += count
        points = pnt + vec * depth[..., None]
        return points, valid
