"""Domain randomisation inside the env: friction drawn at every reset of an env, base mass
drawn once at start, planar pushes every push interval; none of it when disabled."""

from __future__ import annotations

import numpy as np

from .conftest import STAND

RANDOM = [*STAND, "task.num_envs=16", "task.randomization.enabled=true"]


def friction_scale(env) -> np.ndarray:
    nominal = env.sim._nominal_friction
    live = env.sim._friction[:, :, 0]
    return live[:, 0] / nominal[0]


def added_mass(env) -> np.ndarray:
    base = env.sim.base_body
    return env.sim._body_mass[:, base] - env.sim._nominal_mass[base]


def test_friction_is_redrawn_for_the_envs_reset(make_env) -> None:
    cfg, env = make_env(*RANDOM)
    env.reset_all()
    lo, hi = cfg.task.randomization.friction
    first = friction_scale(env).copy()
    assert (lo <= first).all() and (first <= hi).all() and np.unique(first).size == env.num_envs
    # every geom of an env shares the env's scale
    ratio = env.sim._friction[:, :, 0] / env.sim._nominal_friction[None, :]
    np.testing.assert_allclose(ratio, np.broadcast_to(first[:, None], ratio.shape))
    env._reset_envs(np.array([2, 5]))
    after = friction_scale(env)
    changed = np.flatnonzero(~np.isclose(after, first))
    assert changed.tolist() == [2, 5]


def test_base_mass_is_drawn_once(make_env) -> None:
    cfg, env = make_env(*RANDOM)
    lo, hi = cfg.task.randomization.added_base_mass
    mass = added_mass(env).copy()
    assert (lo <= mass).all() and (mass <= hi).all() and np.unique(mass).size == env.num_envs
    env.reset_all()
    np.testing.assert_array_equal(added_mass(env), mass)


def test_pushes_kick_the_due_envs_planar_velocity_only(make_env) -> None:
    cfg, env = make_env(*RANDOM, "task.randomization.push_interval_s=0.1")
    env.reset_all()
    v = cfg.task.randomization.push_velocity
    due = np.arange(env.num_envs) % 2 == 0
    env._episode_steps[:] = np.where(due, env._push_steps, 1)
    before = env.sim.qvel.copy()
    env._maybe_push()
    kick = env.sim.qvel - before
    assert np.abs(kick[~due]).max() == 0.0
    assert np.abs(kick[due][:, 2:]).max() == 0.0
    planar = kick[due][:, :2]
    assert (np.abs(planar) <= v).all() and (np.abs(planar) > 0).all()


def test_nothing_is_randomised_when_disabled(make_env) -> None:
    _, env = make_env(*STAND, "task.randomization.enabled=false")
    env.reset_all()
    assert env.sim._friction is None and env.sim._body_mass is None
    assert env._push_steps == 0
