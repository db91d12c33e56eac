"""N copies of the scene stepping as the worlds of one MuJoCo-Warp model (`sim.backend=warp`).

The interface is `BatchedSim`'s: live (N, ...) numpy arrays `qpos`, `qvel`, `ctrl`, ...,
`sensor(name)`, `data(field)`, `step`, `forward`, `reset`, the per-env friction and base mass,
and the integration state for checkpoints. On warp's CPU device the arrays are the device
arrays themselves (zero copy). On a GPU they are host mirrors: every step pushes `ctrl` and
pulls the state back, a round trip that costs the GPU most of its speed until the task runs
on device tensors (issue 16's remaining part).

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

    def __init__(
        self,
        scene: Scene,
        num_envs: int,
        device: str = "auto",
        seed: int = 0,
        nconmax: int = 0,
        njmax: int = 0,
    ):
        self.scene = scene
        self.model = scene.model
        self.num_envs = num_envs
        self.device = warp_device(device)
        self.on_cpu = wp.get_device(self.device).is_cpu
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
        self.overflows = np.zeros(num_envs, dtype=np.int64)  # steps that overflowed a buffer
        self.solver_limits = np.zeros(num_envs, dtype=np.int64)  # steps at an iteration limit
        # mjData.warning's shape (N, mjNWARNING, 2): warp keeps no warnings; NaNs are caught
        # from the state by the task
        self.warnings = np.zeros((num_envs, N_WARNINGS, 2), np.int32)
        host_layout(self, scene, num_envs, seed)
        self._sensor_adr = {
            self.model.sensor(i).name: (self.model.sensor_adr[i], self.model.sensor_dim[i])
            for i in range(self.model.nsensor)
        }

    def _bind(self, field: str, source=None) -> np.ndarray:
        """The numpy face of a device array: the array itself on the CPU, else a mirror."""
        array = getattr(source if source is not None else self.d, field)
        view = array.numpy()
        self._arrays[field] = (array, view)
        return view

    def _pull(self) -> None:
        if not self.on_cpu:
            for array, view in self._arrays.values():
                view[...] = array.numpy()

    def _push(self) -> None:
        if not self.on_cpu:
            for array, view in self._arrays.values():
                array.assign(view)

    def sensor(self, name: str) -> np.ndarray:
        if name not in self._sensor_adr:
            raise KeyError(f"no sensor '{name}' in the scene")
        adr, dim = self._sensor_adr[name]
        return self.sensordata[:, adr : adr + dim]

    def data(self, field: str) -> np.ndarray:
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
            for _ in range(nstep):
                mjw.step(self.m, self.d)
                flags = self.d.overflow.numpy()
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

    def reset(self, ids: np.ndarray | None = None, noise: ResetConfig | None = None) -> None:
        """Reset `ids` (all if None) to `home` on their own tile, with uniform noise."""
        ids = np.arange(self.num_envs) if ids is None else np.asarray(ids, dtype=np.int64)
        if ids.size == 0:
            return
        keys = np.full(self.num_envs, -1, dtype=np.int32)
        keys[ids] = self.scene.home_key
        self._push()
        with wp.ScopedDevice(self.device):
            mjw.reset_data_keyframe(self.m, self.d, wp.array(keys, dtype=int))
        self._pull()
        place_home(self, ids, noise)
        self.forward(ids)

    def set_friction_scale(self, ids: np.ndarray, scale: np.ndarray) -> None:
        """Sliding friction of every geom of env i = nominal * scale[i]."""
        if self._friction is None:
            self._friction = self._bind("geom_friction", self.m)
        self._friction[ids, :, 0] = self._nominal_friction[None, :] * np.asarray(scale)[:, None]

    def set_added_base_mass(self, ids: np.ndarray, added: np.ndarray) -> None:
        """Pelvis mass of env i = nominal + added[i] kg; derived constants are recomputed."""
        if self._body_mass is None:
            self._body_mass = self._bind("body_mass", self.m)
        self._body_mass[ids, self.base_body] = self._nominal_mass[self.base_body] + added
        self.set_const(ids)

    def set_const(self, ids: np.ndarray) -> None:
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
