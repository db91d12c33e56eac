"""Left/right mirror of the G1's observations and actions (for symmetry augmentation).

Mirroring the world about the robot's sagittal plane swaps every left joint with its right
twin and negates the joints that turn about x (roll) or z (yaw); body-frame vectors flip
their y (linear) or x and z (angular) components; the gait clock moves half a period, which
negates its (sin, cos); height maps flip left for right. Each mirror is a permutation and a
sign per column: mirrored = x[:, perm] * sign.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from lca.task import observations

ROLL_OR_YAW = ("_roll_", "_yaw_")
VECTOR_SIGNS = {
    "base_ang_vel": (-1.0, 1.0, -1.0),  # an axial vector: x and z flip
    "projected_gravity": (1.0, -1.0, 1.0),
    "velocity_commands": (1.0, -1.0, -1.0),  # u_x, u_y, yaw rate
    "phase": (-1.0, -1.0),  # the other foot's clock, half a period later
    "base_lin_vel_world": (1.0, -1.0, 1.0),  # the world mirrored about its x-z plane
}


@dataclass(frozen=True)
class Mirror:
    perm: np.ndarray  # (D,) source column of each mirrored column
    sign: np.ndarray  # (D,)

    def __call__(self, x: np.ndarray) -> np.ndarray:
        return x[..., self.perm] * self.sign


def joint_mirror(joint_names: list[str]) -> Mirror:
    """Swap left_/right_ joints; negate roll and yaw joints (the waist maps onto itself)."""
    index = {name: i for i, name in enumerate(joint_names)}

    def twin(name: str) -> str:
        if name.startswith("left_"):
            return "right_" + name[len("left_") :]
        if name.startswith("right_"):
            return "left_" + name[len("right_") :]
        return name

    perm = np.array([index[twin(n)] for n in joint_names])
    sign = np.array([-1.0 if any(k in n for k in ROLL_OR_YAW) else 1.0 for n in joint_names])
    return Mirror(perm, sign)


def _concat(parts: list[Mirror]) -> Mirror:
    perms, signs, offset = [], [], 0
    for part in parts:
        perms.append(part.perm + offset)
        signs.append(part.sign)
        offset += part.perm.size
    return Mirror(np.concatenate(perms), np.concatenate(signs))


def _term_mirror(name: str, joints: Mirror) -> Mirror:
    if name in ("joint_pos", "joint_vel", "actions"):
        return joints
    sign = np.array(VECTOR_SIGNS[name])
    return Mirror(np.arange(sign.size), sign)


def proprioception_mirrors(joint_names: list[str], obs_cfg) -> dict[str, Mirror]:
    """Mirrors of the flat groups `policy` and `critic`, in the env's layout
    (task.observations: its history length and declared terms)."""
    joints = joint_mirror(joint_names)
    n = len(joint_names)
    history = int(obs_cfg.history)
    frame = [_term_mirror(t.name, joints) for t in observations.history_terms(obs_cfg, n)]
    current = [_term_mirror(t.name, joints) for t in observations.current_terms(obs_cfg, n)]
    policy = _concat(frame * history + current)
    critic = _concat(frame * history + current + [_term_mirror("base_lin_vel_world", joints)])
    return {"policy": policy, "critic": critic, "actions": joints}


def mirror_map(height: np.ndarray) -> np.ndarray:
    """(..., rows, cols) yaw-aligned map, columns running +y to -y: flip the columns."""
    return height[..., ::-1]
