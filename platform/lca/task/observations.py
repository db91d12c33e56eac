"""Observation terms (paper table "Proprioception observation terms") and their history.

Noise is added to the raw value, then the scale applied (IsaacLab's order). The history
holds K frames of (joint_pos, joint_vel, base_ang_vel, projected_gravity), newest first.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from lca.task.state import RobotState


@dataclass(frozen=True)
class Term:
    name: str
    dim: int
    scale: float | tuple[float, ...] = 1.0
    noise: float = 0.0  # half-width of uniform noise on the raw value


def history_terms(num_joints: int) -> tuple[Term, ...]:
    return (
        Term("joint_pos", num_joints, 1.0, 0.01),
        Term("joint_vel", num_joints, 0.05, 1.5),
        Term("base_ang_vel", 3, 0.25, 0.2),
        Term("projected_gravity", 3, 1.0, 0.05),
    )


def current_terms(num_joints: int) -> tuple[Term, ...]:
    return (
        Term("velocity_commands", 3, (2.0, 2.0, 0.25)),
        Term("actions", num_joints),
        Term("phase", 2),  # (sin, cos) of 2 pi phi; zeros while standing
    )


def history_frame(
    state: RobotState,
    default_joint_pos: np.ndarray,
    terms: tuple[Term, ...],
    rng: np.random.Generator | None,
) -> np.ndarray:
    """One (N, D) frame; `rng=None` gives the noiseless (critic) version."""
    raw = {
        "joint_pos": state.joint_pos - default_joint_pos,
        "joint_vel": state.joint_vel,
        "base_ang_vel": state.base_ang_vel,
        "projected_gravity": state.projected_gravity,
    }
    parts = []
    for term in terms:
        value = raw[term.name]
        if rng is not None and term.noise > 0:
            value = value + rng.uniform(-term.noise, term.noise, value.shape)
        parts.append(value * np.asarray(term.scale))
    return np.concatenate(parts, axis=1)


def phase_features(phase: np.ndarray, standing: np.ndarray) -> np.ndarray:
    """(N, 2) sin/cos of the left foot's phase; zero while standing (standing detection)."""
    angle = 2 * np.pi * phase[:, 0]
    feats = np.stack([np.sin(angle), np.cos(angle)], axis=1)
    return feats * (~standing)[:, None]


class History:
    """(N, K, D) buffer, index 0 newest. A reset env's history is filled with its first frame."""

    def __init__(self, num_envs: int, length: int, dim: int):
        self.buffer = np.zeros((num_envs, length, dim))

    def push(self, frame: np.ndarray) -> None:
        self.buffer[:, 1:] = self.buffer[:, :-1]
        self.buffer[:, 0] = frame

    def fill(self, ids: np.ndarray, frame: np.ndarray) -> None:
        self.buffer[ids] = frame[ids, None, :]

    def flat(self) -> np.ndarray:
        """(N, K*D), term-major within each frame, newest frame first."""
        return self.buffer.reshape(self.buffer.shape[0], -1)
