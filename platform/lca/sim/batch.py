"""N copies of the scene stepping in parallel native threads (mjbatch), with live numpy views.

Environment i lives on terrain tile i % n_tiles and is reset to the `home` keyframe moved to
that tile's centre, with noise. Friction and base mass can be set per environment.
"""

from __future__ import annotations

import mjbatch
import mujoco
import numpy as np

from lca.arrays import Array, copy_of, device_of, draw, like, namespace
from lca.sim import robot as g1
from lca.sim.config import ResetConfig
from lca.sim.scene import Scene


def yaw_quat(yaw: Array) -> Array:
    """(N,) heading angles -> (N, 4) wxyz quaternions about +z."""
    xp = namespace(yaw)
    zero = xp.zeros_like(yaw)
    return xp.stack([xp.cos(yaw / 2), zero, zero, xp.sin(yaw / 2)], axis=-1)


def place_home(sim, ids: Array, noise: ResetConfig | None) -> None:
    """Put the just-reset envs `ids` of a batched sim (mjbatch or warp) in the `home` pose on
    their own tile, with uniform noise on position, heading and joints; ctrl holds home.
    Computed in the sim's array type (on warp's device with `tensors`), from `sim.rng`."""
    n = int(ids.shape[0])
    xy = copy_of(sim.env_origin[ids])
    xp = namespace(xy)
    yaw = xp.zeros(n, dtype=xy.dtype, device=device_of(xy))
    home = like(sim.scene.home_joint_pos, xy)
    joints = xp.tile(home, (n, 1))
    if noise is not None:
        xy += draw(sim.rng, -noise.base_xy_noise, noise.base_xy_noise, (n, 2), xy)
        yaw = draw(sim.rng, -noise.yaw_range, noise.yaw_range, n, xy)
        joints += draw(sim.rng, -noise.joint_pos_noise, noise.joint_pos_noise, joints.shape, xy)
    ground = sim.scene.terrain.height_at(xy[:, 0], xy[:, 1])
    qpos = sim.qpos[ids]
    qpos[:, :2] = xy
    qpos[:, 2] = ground + sim.scene.base_height
    qpos[:, 3:7] = yaw_quat(yaw)
    qpos[:, sim.joint_qpos] = joints
    sim.qpos[ids] = qpos
    if noise is not None and noise.joint_vel_noise > 0:
        qvel = sim.qvel[ids]
        v = noise.joint_vel_noise
        qvel[:, sim.joint_dof] = draw(sim.rng, -v, v, tuple(joints.shape), xy)
        sim.qvel[ids] = qvel
    sim.ctrl[ids] = home


def host_layout(sim, scene: Scene, num_envs: int, seed: int) -> None:
    """What every batched sim (mjbatch or warp) keeps on the host: the reset RNG, each env's
    tile and origin, the nominal friction and mass that randomisation scales, the base body
    and the robot's joint slices."""
    sim.rng = np.random.default_rng(seed)
    centres = scene.terrain.tile_centres()
    sim.env_tile = np.arange(num_envs) % len(centres)
    sim.env_origin = centres[sim.env_tile]
    sim._friction = sim._body_mass = None
    sim._nominal_friction = scene.model.geom_friction[:, 0].copy()
    sim._nominal_mass = scene.model.body_mass.copy()
    sim.base_body = mujoco.mj_name2id(scene.model, mujoco.mjtObj.mjOBJ_BODY, g1.BASE_BODY)
    # The robot's joints come first; task objects (a hinged plank) may follow them.
    num_joints = len(scene.joint_names)
    sim.joint_qpos = slice(7, 7 + num_joints)
    sim.joint_dof = slice(6, 6 + num_joints)


class BatchedSim:
    """Live (N, ...) views: `qpos`, `qvel`, `ctrl`, `sensordata`, and `sensor(name)`."""

    steps_subsets = True  # `step(ids=...)` steps only those worlds

    def __init__(self, scene: Scene, num_envs: int, num_threads: int = 0, seed: int = 0):
        self.scene = scene
        self.model = scene.model
        self.num_envs = num_envs
        self.batch = mjbatch.Batch(self.model, num_envs, num_threads=num_threads)
        self.qpos = self.batch.bind("qpos")
        self.qvel = self.batch.bind("qvel")
        self.ctrl = self.batch.bind("ctrl")
        self.qacc = self.batch.bind("qacc")
        self.actuator_force = self.batch.bind("actuator_force")
        self.sensordata = self.batch.bind("sensordata")
        self.time = self.batch.bind("time")
        self.warnings = self.batch.bind("warning")  # (N, mjNWARNING, 2): [lastinfo, number]
        self.overflows = np.zeros(num_envs, dtype=np.int64)  # MuJoCo C grows its buffers
        self._views: dict[str, np.ndarray] = {}
        host_layout(self, scene, num_envs, seed)

    def sensor(self, name: str) -> np.ndarray:
        return self.batch.sensor(name)

    def data(self, field: str) -> np.ndarray:
        """A live (N, ...) view of an mjData field (`xpos`, `cvel`, `subtree_com`, ...). A
        bound field is filled by every later step (kinematics: at the last substep's start);
        the first call fills it with a forward pass, which leaves the state untouched."""
        if field not in self._views:
            self._views[field] = self.batch.bind(field)
            self.batch.forward(None)
        return self._views[field]

    def body_id(self, name: str) -> int:
        """The id of body `name`; a name the model lacks raises, naming it."""
        found = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_BODY, name)
        if found < 0:
            raise KeyError(f"no body '{name}' in the scene")
        return found

    def step(self, nstep: int = 1, ids: np.ndarray | None = None) -> None:
        self.batch.step(ids, nstep=nstep)

    def forward(self, ids: np.ndarray | None = None) -> None:
        self.batch.forward(ids)

    def reset(self, ids: np.ndarray | None = None, noise: ResetConfig | None = None) -> None:
        """Reset `ids` (all if None) to `home` on their own tile, with uniform noise."""
        ids = np.arange(self.num_envs) if ids is None else np.asarray(ids, dtype=np.int64)
        if ids.size == 0:
            return
        self.batch.reset(ids, keyframe=self.scene.home_key)
        place_home(self, ids, noise)
        self.batch.forward(ids)

    def get_state(self) -> np.ndarray:
        """(N, S) integration state (mjSTATE_INTEGRATION), as a checkpoint carries it."""
        return self.batch.bind("state").copy()

    def set_state(self, state: np.ndarray) -> None:
        self.batch.bind("state")[:] = state

    def set_const(self, ids: np.ndarray) -> None:
        """Derived model constants of `ids` recomputed after a model change."""
        self.batch.set_const(np.asarray(ids))

    def set_friction_scale(self, ids: np.ndarray, scale: np.ndarray) -> None:
        """Sliding friction of every geom of env i = nominal * scale[i]."""
        if self._friction is None:
            self._friction = self.batch.expand("geom_friction")
        self._friction[ids, :, 0] = self._nominal_friction[None, :] * np.asarray(scale)[:, None]

    def set_added_base_mass(self, ids: np.ndarray, added: np.ndarray) -> None:
        """Pelvis mass of env i = nominal + added[i] kg; derived constants are recomputed."""
        if self._body_mass is None:
            self._body_mass = self.batch.expand("body_mass")
        self._body_mass[ids, self.base_body] = self._nominal_mass[self.base_body] + added
        self.set_const(ids)
