"""The G1's left/right mirror: an involution that swaps twins with the right signs, and that
commutes with the simulator: observing a mirrored robot gives the mirrored observation."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from lca.learn import symmetry as learn_symmetry
from lca.task import heightmap, observations
from lca.task.env import LocomotionEnv
from lca.task.state import read_state
from lca.task.symmetry import joint_mirror, mirror_map, proprioception_mirrors

from .conftest import STAND


@pytest.fixture(scope="module")
def env(make_env) -> LocomotionEnv:
    _, env = make_env(*STAND, "task.num_envs=2", "task.observations.noise=false")
    return env


def test_joint_mirror_swaps_twins_and_flips_roll_and_yaw(env):
    names = env.scene.joint_names
    m = joint_mirror(names)
    at = {n: i for i, n in enumerate(names)}
    for side, other in (("left", "right"), ("right", "left")):
        for joint, sign in (
            ("hip_pitch", 1),
            ("hip_roll", -1),
            ("hip_yaw", -1),
            ("knee", 1),
            ("ankle_pitch", 1),
            ("ankle_roll", -1),
            ("shoulder_roll", -1),
            ("shoulder_yaw", -1),
            ("elbow", 1),
            ("wrist_roll", -1),
            ("wrist_pitch", 1),
            ("wrist_yaw", -1),
        ):
            i = at[f"{side}_{joint}_joint"]
            assert names[m.perm[i]] == f"{other}_{joint}_joint"
            assert m.sign[i] == sign
    for joint, sign in (("waist_yaw", -1), ("waist_roll", -1), ("waist_pitch", 1)):
        i = at[f"{joint}_joint"]
        assert m.perm[i] == i and m.sign[i] == sign


def test_mirroring_twice_is_the_identity(env):
    rng = np.random.default_rng(0)
    maps = proprioception_mirrors(env.scene.joint_names, env.task_cfg.observations)
    for mirror in maps.values():
        x = rng.normal(size=(4, mirror.perm.size))
        np.testing.assert_array_equal(mirror(mirror(x)), x)
        assert sorted(mirror.perm) == list(range(mirror.perm.size))  # a permutation
    grid = rng.normal(size=(3, 1, 11, 11))
    np.testing.assert_array_equal(mirror_map(mirror_map(grid)), grid)


def test_map_mirror_maps_each_cell_to_its_reflection():
    offsets = heightmap.grid_offsets((11, 11), 0.1).reshape(11, 11, 2)
    flipped = mirror_map(offsets.transpose(2, 0, 1)).transpose(1, 2, 0)
    np.testing.assert_allclose(flipped[..., 0], offsets[..., 0])
    np.testing.assert_allclose(flipped[..., 1], -offsets[..., 1])


def _mirror_state(env: LocomotionEnv) -> None:
    """Row 1 := the reflection of row 0 about the world x-z plane (row 0 faces +x)."""
    sim, jm = env.sim, joint_mirror(env.scene.joint_names)
    qpos, qvel = sim.qpos[0].copy(), sim.qvel[0].copy()
    joints, dofs = sim.joint_qpos, sim.joint_dof
    qpos[1] *= -1  # base y
    qpos[3:7] *= [1, -1, 1, -1]  # quaternion: R -> M R M with M = diag(1, -1, 1)
    qpos[joints] = jm(qpos[joints])
    qvel[1] *= -1  # world linear velocity
    qvel[3:6] *= [-1, 1, -1]  # body angular velocity, an axial vector
    qvel[dofs] = jm(qvel[dofs])
    sim.qpos[1], sim.qvel[1] = qpos, qvel


def test_observing_the_mirrored_robot_gives_the_mirrored_observation(env):
    rng = np.random.default_rng(1)
    sim = env.sim
    env.reset_all()
    qpos, qvel = sim.qpos[0].copy(), sim.qvel[0].copy()
    qpos[2] += 0.05
    half_roll, half_pitch = 0.1, -0.07  # tilted, heading +x
    qpos[3:7] = [np.cos(half_roll) * np.cos(half_pitch), np.sin(half_roll), np.sin(half_pitch), 0]
    qpos[3:7] /= np.linalg.norm(qpos[3:7])
    qpos[sim.joint_qpos] += rng.uniform(-0.3, 0.3, env.num_actions)
    qvel[:] = rng.uniform(-1, 1, qvel.shape)
    sim.qpos[0], sim.qvel[0] = qpos, qvel
    _mirror_state(env)
    sim.forward()
    jm = joint_mirror(env.scene.joint_names)
    env.commands.value[0] = [0.4, 0.2, -0.3]
    env.commands.value[1] = [0.4, -0.2, 0.3]
    period_steps = round(env.task_cfg.reward_params.gait_period / env.dt)
    env._episode_steps[:] = [3, 3 + period_steps // 2]  # the other foot's clock
    env.action[0] = rng.uniform(-1, 1, env.num_actions)
    env.action[1] = jm(env.action[0])
    obs = env._observe(read_state(env.sim, env.contacts), reset_ids=np.arange(2))

    mirrored = learn_symmetry.mirror_observations(env, obs[:1])
    for group in ("policy", "critic"):
        np.testing.assert_allclose(
            obs[group][1].numpy(), mirrored[group][0].numpy(), atol=1e-5, err_msg=group
        )
    actions = torch.as_tensor(env.action[:1], dtype=torch.float32)
    np.testing.assert_allclose(
        learn_symmetry.mirror_actions(env, actions)[0].numpy(), env.action[1], atol=1e-6
    )


def test_augment_appends_the_mirror_images(env):
    obs = env.get_observations()
    actions = torch.randn(env.num_envs, env.num_actions)
    aug_obs, aug_actions = learn_symmetry.augment(env, obs, actions)
    assert aug_obs.batch_size[0] == 2 * env.num_envs
    torch.testing.assert_close(aug_obs[: env.num_envs]["policy"], obs["policy"])
    torch.testing.assert_close(aug_actions[: env.num_envs], actions)
    torch.testing.assert_close(
        aug_obs[env.num_envs :]["height"], torch.flip(obs["height"], dims=[-1])
    )
    declared = observations.history_terms(env.task_cfg.observations, env.num_actions)
    frame = sum(t.dim for t in declared)
    assert aug_obs["policy"].shape[1] == obs["policy"].shape[1] > frame
