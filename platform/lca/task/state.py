"""What the task reads from the simulation each policy step, in the sim's array type: NumPy
for mjbatch, torch tensors for views of warp's arrays (lca.arrays).

Contact quantities are maxima over the physics substeps of one policy step, so a short
impact between two policy steps still counts.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from lca.arrays import Array, device_of, namespace, zeros
from lca.sim import robot as g1
from lca.sim.batch import BatchedSim


def quat_to_mat(q: Array) -> Array:
    """(..., 4) wxyz -> (..., 3, 3)."""
    xp = namespace(q)
    w, x, y, z = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    rows = (
        (1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)),
        (2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)),
        (2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)),
    )
    return xp.stack([xp.stack(row, axis=-1) for row in rows], axis=-2)


def yaw_of(q: Array) -> Array:
    w, x, y, z = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    return namespace(q).atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))


def pitch_of(q: Array) -> Array:
    """Pitch (rad) of a frame's x-axis out of the horizontal plane."""
    xp, m = namespace(q), quat_to_mat(q)
    return xp.atan2(-m[..., 2, 0], xp.hypot(m[..., 0, 0], m[..., 1, 0]))


@dataclass
class RobotState:
    base_pos: Array  # (N, 3) world
    base_quat: Array  # (N, 4) wxyz
    base_lin_vel: Array  # (N, 3) body frame
    base_lin_vel_world: Array  # (N, 3) world frame (critic, as in the paper)
    base_ang_vel: Array  # (N, 3) body frame
    projected_gravity: Array  # (N, 3) unit gravity in the body frame
    base_height: Array  # (N,) above the terrain under the base
    joint_pos: Array  # (N, J)
    joint_vel: Array  # (N, J)
    joint_acc: Array  # (N, J)
    torque: Array  # (N, J) actuator torques
    foot_pos: Array  # (N, 2, 3) sole sites, left then right
    foot_vel: Array  # (N, 2, 3) world
    foot_pitch: Array  # (N, 2)
    foot_height: Array  # (N, 2) above the terrain under each sole
    foot_force: Array  # (N, 2) max over substeps of |ground reaction|
    foot_lateral_force: Array  # (N, 2) max over substeps of |F_xy|
    leg_contact_force: Array  # (N, B) max over substeps, undesired leg bodies


class ContactAccumulator:
    """Tracks contact-force maxima over the substeps of one policy step, in the sim's array
    type (NumPy for mjbatch, torch for views of warp's arrays)."""

    def __init__(self, sim: BatchedSim):
        self.sim = sim
        names = [f"{side}_foot_contact" for side in g1.FEET] + [
            f"{side}_{part}_contact" for side in g1.FEET for part in g1.UNDESIRED_CONTACT_BODIES
        ]
        # the force columns (1-3) of every contact sensor, gathered in one take per substep
        adr = [int(sim.scene.model.sensor(name).adr[0]) for name in names]
        columns = np.array([a + k for a in adr for k in (1, 2, 3)], dtype=np.int64)
        self.xp = namespace(sim.qpos)  # resolved once: update runs every substep
        self._columns = self.xp.asarray(columns, device=device_of(sim.qpos))
        self._shape = (sim.num_envs, len(names), 3)

        self.foot_force = zeros((sim.num_envs, len(g1.FEET)), sim.qpos)
        self.foot_lateral = zeros((sim.num_envs, len(g1.FEET)), sim.qpos)
        self.leg_force = zeros((sim.num_envs, len(names) - len(g1.FEET)), sim.qpos)

    def clear(self) -> None:
        self.foot_force[:] = 0
        self.foot_lateral[:] = 0
        self.leg_force[:] = 0

    def update(self) -> None:
        xp = self.xp
        force = xp.reshape(xp.take(self.sim.sensordata, self._columns, axis=1), self._shape)
        magnitude = xp.linalg.vector_norm(force, axis=2)
        feet = len(g1.FEET)
        lateral = xp.linalg.vector_norm(force[:, :feet, :2], axis=2)
        self.foot_force[:] = xp.maximum(self.foot_force, magnitude[:, :feet])
        self.foot_lateral[:] = xp.maximum(self.foot_lateral, lateral)
        self.leg_force[:] = xp.maximum(self.leg_force, magnitude[:, feet:])


def read_state(
    sim: BatchedSim, contacts: ContactAccumulator, ids: Array | None = None
) -> RobotState:
    """The state of every env, or only of the rows `ids` (e.g. the envs just reset), as
    copies in the sim's array type."""
    rows = slice(None) if ids is None else ids
    height_at = sim.scene.terrain.height_at
    xp = namespace(sim.qpos)

    def copy(value: Array) -> Array:
        return xp.asarray(value, copy=True)

    def sensor(name: str) -> Array:
        return sim.sensor(name)[rows]  # fancy indexing copies; a slice does not

    qpos, qvel = sim.qpos[rows], sim.qvel[rows]
    base_pos = copy(qpos[:, :3])
    foot_pos = xp.stack([sensor(f"{s}_foot_pos") for s in g1.FEET], axis=1)
    foot_quat = xp.stack([sensor(f"{s}_foot_quat") for s in g1.FEET], axis=1)
    # the ground under the base and each foot, in one query: (N, 1 + feet)
    points = xp.concat([base_pos[:, None, :2], foot_pos[..., :2]], axis=1)
    ground = height_at(points[..., 0], points[..., 1])
    return RobotState(
        base_pos=base_pos,
        base_quat=copy(qpos[:, 3:7]),
        base_lin_vel=copy(sensor("imu_lin_vel")),
        base_lin_vel_world=copy(sensor("base_lin_vel_world")),
        base_ang_vel=copy(sensor("imu_ang_vel")),
        projected_gravity=-sensor("imu_up"),
        base_height=base_pos[:, 2] - ground[:, 0],
        joint_pos=copy(qpos[:, sim.joint_qpos]),
        joint_vel=copy(qvel[:, sim.joint_dof]),
        joint_acc=copy(sim.qacc[rows][:, sim.joint_dof]),
        torque=copy(sim.actuator_force[rows]),
        foot_pos=foot_pos,
        foot_vel=xp.stack([sensor(f"{s}_foot_lin_vel") for s in g1.FEET], axis=1),
        foot_pitch=pitch_of(foot_quat),
        foot_height=foot_pos[..., 2] - ground[:, 1:],
        foot_force=copy(contacts.foot_force[rows]),
        foot_lateral_force=copy(contacts.foot_lateral[rows]),
        leg_contact_force=copy(contacts.leg_force[rows]),
    )


def zero_rows(state: RobotState, broken: Array) -> RobotState:
    """Zero the rows of broken envs: `non_finite` flags every row holding a NaN or inf."""
    if broken.any():
        for value in vars(state).values():
            value[broken] = 0.0
    return state


def replace_rows(state: RobotState, fresh: RobotState, ids: Array) -> RobotState:
    """Put `fresh` (the state of rows `ids` only) into `state`."""
    for name, value in vars(state).items():
        value[ids] = getattr(fresh, name)
    return state
