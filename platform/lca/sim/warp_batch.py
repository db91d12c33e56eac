"""N copies of the scene stepping as the worlds of one MuJoCo-Warp model (`sim.backend=warp`).

The interface is `BatchedSim`'s: live (N, ...) arrays `qpos`, `qvel`, `ctrl`, ...,
`sensor(name)`, `data(field)`, `step`, `forward`, `reset`, the per-env friction and base mass,
and the integration state for checkpoints. With `tensors=True` (what the task asks for) the
arrays are torch tensors on warp's device, zero copy through `wp.to_torch`, and resets,
randomisation and the overflow counts stay on the device too: nothing crosses to the host per
step. Otherwise they are NumPy: the device arrays themselves on warp's CPU device, host
mirrors on a GPU (every step pushes `ctrl` and pulls the state back).

Warp computes in float32 (mjbatch: float64); the parity tests state the tolerance. Steps that
overflow a contact or constraint buffer are counted per world (`overflows`, logged by the env
as Sim/buffer_overflows_total) and steps at the solver's iteration limits apart
(`solver_limits`); warp prints neither.
"""

from __future__ import annotations

import warnings

import mujoco
import mujoco_warp as mjw
import numpy as np
import warp as wp

from lca.arrays import Array, device_of, generator, like, namespace, zeros
from lca.sim.batch import BatchedSim, host_layout, place_home
from lca.sim.config import ResetConfig
from lca.sim.scene import Scene

# the fields a checkpoint carries (MuJoCo's mjSTATE_INTEGRATION, without mocap and user data)
STATE_FIELDS = ("time", "qpos", "qvel", "act", "qacc_warmstart", "ctrl")
CONTACTS_PER_GEOM = 4  # a sphere on a heightfield touches up to a few prisms
ROWS_PER_CONTACT = 4  # pyramidal friction cone, condim 3: 2 (condim - 1) rows
# overflow bits of a buffer too small (contacts dropped); the solver's iteration limits
# (ITERATIONS, LS_ITERATIONS) are counted apart: bounded solver work is the config's choice
N_WARNINGS = int(mujoco.mjtWarning.mjNWARNING)
SOLVER_LIMITS = int(mjw.OverflowType.ITERATIONS | mjw.OverflowType.LS_ITERATIONS)


def warp_device(name: str) -> str:
    """`auto`: the first CUDA device when warp sees one, else warp's CPU device."""
    wp.init()
    if name == "auto":
        return "cuda:0" if wp.is_cuda_available() else "cpu"
    return name


def buffer_sizes(model: mujoco.MjModel) -> tuple[int, int]:
    """(contacts, constraint rows) per world, from the geoms that collide with anything:
    every such geom touching the ground in a few points, plus the joint limits."""
    colliding = int(np.count_nonzero((model.geom_contype | model.geom_conaffinity) > 0))
    nconmax = max(8, CONTACTS_PER_GEOM * colliding)
    limits = int(np.count_nonzero(model.jnt_limited))
    return nconmax, ROWS_PER_CONTACT * nconmax + limits + model.neq * 6


class WarpSim:
    """Live (N, ...) arrays `qpos`, `qvel`, `ctrl`, `sensordata`, and `sensor(name)`."""

    steps_subsets = False  # every world steps at once

    def __init__(
        self,
        scene: Scene,
        num_envs: int,
        device: str = "auto",
        seed: int = 0,
        nconmax: int = 0,
        njmax: int = 0,
        tensors: bool = False,
    ):
        self.scene = scene
        self.model = scene.model
        self.num_envs = num_envs
        self.device = warp_device(device)
        self.on_cpu = wp.get_device(self.device).is_cpu
        self.tensors = tensors
        self.mirrored = not (tensors or self.on_cpu)  # NumPy host copies of device arrays
        sizes = buffer_sizes(self.model)
        self.nconmax, self.njmax = nconmax or sizes[0], njmax or sizes[1]
        with wp.ScopedDevice(self.device):
            batched = {"geom_friction": num_envs, "body_mass": num_envs}
            with warnings.catch_warnings():
                # a capsule on a heightfield makes one contact in warp (MuJoCo C: several);
                # the parity tests measure what that changes
                warnings.filterwarnings("ignore", "MULTICCD is enabled")
                self.m = mjw.put_model(self.model, batch_sizes=batched)
            self.m.opt.warn_overflow = 0  # counted in `overflows` instead
            self.d = mjw.make_data(
                self.model, nworld=num_envs, nconmax=self.nconmax, njmax=self.njmax
            )
        self._arrays: dict[str, tuple[wp.array, np.ndarray]] = {}
        self.qpos, self.qvel = self._bind("qpos"), self._bind("qvel")
        self.ctrl, self.qacc = self._bind("ctrl"), self._bind("qacc")
        self.actuator_force = self._bind("actuator_force")
        self.sensordata, self.time = self._bind("sensordata"), self._bind("time")
        ref = self.qpos
        xp = namespace(ref)
        self.overflows = zeros(num_envs, ref, xp.int64)  # steps that overflowed a buffer
        self.solver_limits = zeros(num_envs, ref, xp.int64)  # steps at an iteration limit
        # mjData.warning's shape (N, mjNWARNING, 2): warp keeps no warnings; NaNs are caught
        # from the state by the task
        self.warnings = zeros((num_envs, N_WARNINGS, 2), ref, xp.int32)
        host_layout(self, scene, num_envs, seed)
        if tensors:  # what resets and randomisation read, on the device
            self.rng = generator(seed, ref)
            self.env_origin = like(self.env_origin, ref)
            self._nominal_friction = like(self._nominal_friction, ref)
            self._nominal_mass = like(self._nominal_mass, ref)
        self._sensor_adr = {
            self.model.sensor(i).name: (self.model.sensor_adr[i], self.model.sensor_dim[i])
            for i in range(self.model.nsensor)
        }

    def _bind(self, field: str, source=None) -> Array:
        """The live face of a device array: a torch view (`tensors`), else NumPy: the array
        itself on the CPU, a host mirror on a GPU."""
        array = getattr(source if source is not None else self.d, field)
        view = wp.to_torch(array) if self.tensors else array.numpy()
        self._arrays[field] = (array, view)
        return view

    def _pull(self) -> None:
        if self.mirrored:
            for array, view in self._arrays.values():
                view[...] = array.numpy()

    def _push(self) -> None:
        if self.mirrored:
            for array, view in self._arrays.values():
                array.assign(view)

    def sensor(self, name: str) -> Array:
        if name not in self._sensor_adr:
            raise KeyError(f"no sensor '{name}' in the scene")
        adr, dim = self._sensor_adr[name]
        return self.sensordata[:, adr : adr + dim]

    def data(self, field: str) -> Array:
        """A live (N, ...) view of a Data field (`xpos`, `cvel`, `subtree_com`, ...)."""
        if field not in self._arrays:
            self._bind(field)
            self.forward(None)
        return self._arrays[field][1]

    body_id = BatchedSim.body_id  # reads only the host model

    def step(self, nstep: int = 1, ids: np.ndarray | None = None) -> None:
        if ids is not None:
            raise NotImplementedError("sim.backend=warp steps every world at once")
        self._push()
        with wp.ScopedDevice(self.device):
            overflow = wp.to_torch(self.d.overflow) if self.tensors else None
            for _ in range(nstep):
                mjw.step(self.m, self.d)
                flags = overflow if self.tensors else self.d.overflow.numpy()
                self.overflows += (flags & ~SOLVER_LIMITS) != 0
                self.solver_limits += (flags & SOLVER_LIMITS) != 0
                self.d.overflow.zero_()  # sticky in warp: a count per step instead
        self._pull()

    def forward(self, ids: np.ndarray | None = None) -> None:
        """Recompute positions, velocities and sensors from the state. Warp has no per-world
        forward: every world is recomputed, which leaves each world's state unchanged."""
        self._push()
        with wp.ScopedDevice(self.device):
            mjw.forward(self.m, self.d)
        self._pull()

    def reset(self, ids: Array | None = None, noise: ResetConfig | None = None) -> None:
        """Reset `ids` (all if None) to `home` on their own tile, with uniform noise."""
        xp = namespace(self.qpos)
        if ids is None:
            ids = xp.arange(self.num_envs, device=device_of(self.qpos))
        if int(ids.shape[0]) == 0:
            return
        keys = xp.full(self.num_envs, -1, dtype=xp.int32, device=device_of(self.qpos))
        keys[ids] = self.scene.home_key
        keys = wp.from_torch(keys) if self.tensors else wp.array(keys, dtype=int)
        self._push()
        with wp.ScopedDevice(self.device):
            mjw.reset_data_keyframe(self.m, self.d, keys)
        self._pull()
        place_home(self, ids, noise)
        self.forward(ids)

    def set_friction_scale(self, ids: Array, scale: Array) -> None:
        """Sliding friction of every geom of env i = nominal * scale[i]."""
        if self._friction is None:
            self._friction = self._bind("geom_friction", self.m)
        scale = like(scale, self._nominal_friction)
        self._friction[ids, :, 0] = self._nominal_friction[None, :] * scale[:, None]

    def set_added_base_mass(self, ids: Array, added: Array) -> None:
        """Pelvis mass of env i = nominal + added[i] kg; derived constants are recomputed."""
        if self._body_mass is None:
            self._body_mass = self._bind("body_mass", self.m)
        added = like(added, self._nominal_mass)
        self._body_mass[ids, self.base_body] = self._nominal_mass[self.base_body] + added
        self.set_const(ids)

    def set_const(self, ids: Array) -> None:
        """Derived model constants recomputed (every world: warp has no per-world form)."""
        self._push()
        with wp.ScopedDevice(self.device):
            mjw.set_const(self.m, self.d)
        self._pull()

    def get_state(self) -> np.ndarray:
        """(N, S) integration state, as a checkpoint carries it."""
        return np.concatenate(
            [
                np.asarray(getattr(self.d, f).numpy(), np.float64).reshape(self.num_envs, -1)
                for f in STATE_FIELDS
            ],
            axis=1,
        )

    def set_state(self, state: np.ndarray) -> None:
        start = 0
        for field in STATE_FIELDS:
            array = getattr(self.d, field)
            width = int(np.prod(array.shape[1:])) if array.ndim > 1 else 1
            value = state[:, start : start + width].reshape(array.shape)
            array.assign(value.astype(array.numpy().dtype))
            start += width
        self._pull()
        self.forward()
