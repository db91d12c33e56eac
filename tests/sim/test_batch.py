"""Batched stepping: determinism and the per-environment randomisation hooks."""

from __future__ import annotations

import numpy as np

from lca.sim.batch import BatchedSim
from lca.sim.scene import Scene, build_scene

NUM_ENVS = 8
GRAVITY = 9.81


def total_foot_force_z(sim: BatchedSim) -> np.ndarray:
    """Net vertical contact force on both feet, (N,); negative when the ground pushes up."""
    return sim.sensor("left_foot_contact")[:, 3] + sim.sensor("right_foot_contact")[:, 3]


def rollout(scene: Scene, cfg, seed: int, num_threads: int, steps: int = 100) -> np.ndarray:
    """qpos after each of `steps` policy steps of seeded random targets around home, (T, N, nq)."""
    sim = BatchedSim(scene, NUM_ENVS, num_threads=num_threads, seed=seed)
    sim.reset(noise=cfg.task.reset)
    targets = np.random.default_rng(123).uniform(-0.3, 0.3, (steps, NUM_ENVS, 29))
    history = np.empty((steps, NUM_ENVS, scene.model.nq))
    for t in range(steps):
        sim.ctrl[:] = scene.home_joint_pos + targets[t]
        sim.step(nstep=2)
        history[t] = sim.qpos
    return history


def test_identical_rollouts(mixed_cfg, mixed_scene: Scene) -> None:
    twin = build_scene(mixed_cfg)  # built again from the same config
    np.testing.assert_array_equal(twin.model.hfield_data, mixed_scene.model.hfield_data)
    np.testing.assert_array_equal(twin.home_qpos, mixed_scene.home_qpos)
    a = rollout(mixed_scene, mixed_cfg, seed=0, num_threads=1)
    b = rollout(twin, mixed_cfg, seed=0, num_threads=2)
    assert np.all(np.isfinite(a))
    assert np.array_equal(a, b)
    # The rollout went somewhere: envs moved, and differ from each other (reset noise).
    assert np.abs(a[-1] - a[0]).max() > 0.01
    assert not np.array_equal(a[:, 0, 7:], a[:, 4, 7:])
    # Another seed draws other reset noise.
    c = rollout(mixed_scene, mixed_cfg, seed=1, num_threads=2, steps=1)
    assert not np.array_equal(a[0], c[0])


def test_reset_places_envs_on_their_tiles(mixed_cfg, mixed_scene: Scene) -> None:
    sim = BatchedSim(mixed_scene, NUM_ENVS, num_threads=1, seed=0)
    noise = mixed_cfg.task.reset
    sim.reset(noise=noise)
    xy = sim.qpos[:, :2]
    assert np.all(np.abs(xy - sim.env_origin) <= noise.base_xy_noise + 1e-12)
    ground = mixed_scene.terrain.height_at(xy[:, 0], xy[:, 1])
    np.testing.assert_allclose(sim.qpos[:, 2], ground + mixed_scene.base_height)
    joint_dev = sim.qpos[:, 7:] - mixed_scene.home_joint_pos
    assert np.abs(joint_dev).max() <= noise.joint_pos_noise + 1e-12
    assert np.abs(joint_dev).max() > 0
    np.testing.assert_array_equal(sim.ctrl, np.tile(mixed_scene.home_joint_pos, (NUM_ENVS, 1)))


def test_added_base_mass_changes_ground_reaction(flat_scene: Scene) -> None:
    added = np.array([0.0, 3.0, -1.0])
    sim = BatchedSim(flat_scene, len(added), num_threads=1)
    sim.reset()
    sim.set_added_base_mass(np.arange(len(added)), added)
    sim.step(nstep=200)  # settle for 1 s
    force = np.zeros(len(added))
    for _ in range(20):
        sim.step()
        force += total_foot_force_z(sim) / 20
    mass = flat_scene.model.body_subtreemass[0] + added
    np.testing.assert_allclose(-force, mass * GRAVITY, rtol=0.02)
    # The difference is the added weight, not noise.
    np.testing.assert_allclose(force[0] - force[1:], added[1:] * GRAVITY, rtol=0.1)


def test_friction_scale_changes_per_sim_model(flat_scene: Scene) -> None:
    sim = BatchedSim(flat_scene, 4, num_threads=2)
    sim.reset()
    nominal = flat_scene.model.geom_friction[:, 0]
    sim.set_friction_scale(np.array([1, 2]), np.array([0.1, 1.25]))  # envs 0 and 3 untouched
    friction = sim.batch.expand("geom_friction")[:, :, 0]
    np.testing.assert_allclose(friction[[0, 3]], [nominal, nominal])
    np.testing.assert_allclose(friction[1], 0.1 * nominal)
    np.testing.assert_allclose(friction[2], 1.25 * nominal)
    # The torsional/rolling columns are not scaled.
    rest = sim.batch.expand("geom_friction")[:, :, 1:]
    assert np.all(rest == flat_scene.model.geom_friction[None, :, 1:])
    # ...and physics sees it: put every env in the same state (all tiles are flat), shove them
    # at 1 m/s; the two nominal envs stay bitwise identical, the others diverge.
    sim.qpos[:, :2] = sim.env_origin[0]
    sim.forward()
    sim.step(nstep=20)
    sim.qvel[:, 0] = 1.0
    sim.step(nstep=40)
    assert np.all(np.isfinite(sim.qpos))
    assert np.array_equal(sim.qpos[0], sim.qpos[3])
    assert not np.array_equal(sim.qpos[0], sim.qpos[1])
    assert not np.array_equal(sim.qpos[0], sim.qpos[2])
    # Macroscopically for mu = 0.1, not by rounding.
    assert np.abs(sim.qpos[1] - sim.qpos[0]).max() > 1e-2


def test_added_base_mass_only_touches_given_envs(flat_scene: Scene) -> None:
    sim = BatchedSim(flat_scene, 3, num_threads=1)
    sim.set_added_base_mass(np.array([0, 1]), np.array([2.0, 2.0]))
    mass = sim.batch.expand("body_mass")[:, sim.base_body]
    nominal = flat_scene.model.body_mass[sim.base_body]
    np.testing.assert_allclose(mass, [nominal + 2, nominal + 2, nominal])
