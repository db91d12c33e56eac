"""From a policy's actions to joint targets: the per-joint action scale, and joint groups."""

from __future__ import annotations

import mujoco
import numpy as np


def joint_ids(names: list[str], *patterns: str) -> np.ndarray:
    """Indices of the joints whose name contains any of `patterns`."""
    return np.array([i for i, n in enumerate(names) if any(p in n for p in patterns)], dtype=int)


def action_scales(model: mujoco.MjModel, task) -> np.ndarray:
    """(J,) rad per unit action: one scale, or scale * effort limit / kp per joint."""
    n = model.nu
    if not task.action_scale_by_effort:
        return np.full(n, float(task.action_scale))
    kp = model.actuator_gainprm[:, 0]
    effort = model.actuator_forcerange[:, 1]
    return float(task.action_scale) * effort / kp
