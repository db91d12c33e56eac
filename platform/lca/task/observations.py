"""Observation terms (paper table "Proprioception observation terms") and their history.

Terms are declared in task.observations (name, scale, noise, clip) and registered here by
name; `build` serves the env and `lca.describe` alike. Noise is added to the raw value, then
the scale applied (IsaacLab's order). The history holds K frames of the proprioception terms
(the paper's: joint_pos, joint_vel, base_ang_vel, projected_gravity), newest first. Like the
reward terms, they run on NumPy arrays and torch tensors alike (lca.arrays).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from lca.arrays import Array, device_of, like, namespace, uniform
from lca.config.registry import OBS_TERMS
from lca.task.state import RobotState


@dataclass(frozen=True)
class Term:
    """One declared observation term (task.observations), resolved: its dimension and the
    registered function that reads its raw value (looked up once, not every step)."""

    name: str
    dim: int
    scale: float | tuple[float, ...] = 1.0
    noise: float = 0.0  # half-width of uniform noise on the raw value
    clip: float | None = None
    value: Callable[[ObsInputs], Array] | None = field(default=None, compare=False)


@dataclass
class ObsInputs:
    """What observation terms read: the robot state and the task's signals of this step."""

    state: RobotState
    default_joint_pos: Array
    command: Array  # (N, 3)
    action: Array  # (N, J)
    phase: Array  # (N, 2)
    standing: Array  # (N,) bool


@dataclass(frozen=True)
class ObsTerm:
    dim: Callable[[int], int]  # of the joint count
    value: Callable[[ObsInputs], Array]  # (N, dim), raw (before noise and scale)


def terms(declared, num_joints: int) -> tuple[Term, ...]:
    """The declared terms (task.observations.proprioception or .current) with dimensions."""
    out = []
    for t in declared:
        scale = (
            tuple(float(x) for x in t.scale) if not isinstance(t.scale, int | float) else t.scale
        )
        term = OBS_TERMS[t.name]
        out.append(Term(t.name, term.dim(num_joints), scale, t.noise, t.clip, term.value))
    return tuple(out)


def history_terms(obs_cfg, num_joints: int) -> tuple[Term, ...]:
    return terms(obs_cfg.proprioception, num_joints)


def current_terms(obs_cfg, num_joints: int) -> tuple[Term, ...]:
    return terms(obs_cfg.current, num_joints)


def build(inputs: ObsInputs, declared: tuple[Term, ...], rng: Any | None) -> Array:
    """(N, D): each term's raw value, plus noise (unless `rng` is None: the critic's clean
    version), times its scale, clipped; noise before scale, as IsaacLab does. `rng`: a NumPy
    Generator for NumPy arrays, a torch.Generator on the tensors' device for torch."""
    parts = []
    for term in declared:
        value = term.value(inputs)
        xp = namespace(value)
        if rng is not None and term.noise > 0:
            value = value + uniform(rng, term.noise, value)
        value = value * like(term.scale, value)
        if term.clip is not None:
            value = xp.clip(value, min=-term.clip, max=term.clip)
        parts.append(value)
    return namespace(*parts).concat(parts, axis=1)


def phase_features(phase: Array, standing: Array) -> Array:
    """(N, 2) sin/cos of the left foot's phase; zero while standing (standing detection)."""
    xp = namespace(phase)
    angle = 2 * xp.pi * phase[:, 0]
    feats = xp.stack([xp.sin(angle), xp.cos(angle)], axis=1)
    return feats * (~standing)[:, None]


class History:
    """(N, K, D) buffer, index 0 newest. A reset env's history is filled with its first frame.
    `reference` gives the array type, dtype and device (default: NumPy float64)."""

    def __init__(self, num_envs: int, length: int, dim: int, reference: Array | None = None):
        reference = np.zeros(0) if reference is None else reference
        xp = namespace(reference)
        self.buffer = xp.zeros(
            (num_envs, length, dim), dtype=reference.dtype, device=device_of(reference)
        )

    def push(self, frame: Array) -> None:
        xp = namespace(frame)
        # a new buffer, not an overlapping in-place shift, which torch does not allow
        self.buffer = xp.concat([frame[:, None, :], self.buffer[:, :-1]], axis=1)

    def fill(self, ids: Array, frame: Array) -> None:
        self.buffer[ids] = frame[ids, None, :]

    def flat(self) -> Array:
        """(N, K*D), term-major within each frame, newest frame first."""
        return namespace(self.buffer).reshape(self.buffer, (self.buffer.shape[0], -1))


def _register(name: str, dim: Callable[[int], int], value: Callable[[ObsInputs], Array]):
    OBS_TERMS.register(name)(ObsTerm(dim, value))


_register("joint_pos", lambda j: j, lambda o: o.state.joint_pos - o.default_joint_pos)
_register("joint_vel", lambda j: j, lambda o: o.state.joint_vel)
_register("base_ang_vel", lambda j: 3, lambda o: o.state.base_ang_vel)
_register("projected_gravity", lambda j: 3, lambda o: o.state.projected_gravity)
_register("velocity_commands", lambda j: 3, lambda o: o.command)
_register("actions", lambda j: j, lambda o: o.action)
# (sin, cos) of 2 pi phi of the left foot; zeros while standing (standing detection)
_register("phase", lambda j: 2, lambda o: phase_features(o.phase, o.standing))
