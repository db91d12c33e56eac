"""One definition of each task term for both backends' arrays: every reward term,
observation group, the history and the terminations give the same values on torch tensors
as on the NumPy arrays the env computed them from (issue 16: sim.backend=warp on a GPU hands
the task torch tensors)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
import torch

from lca.config.registry import REWARD_TERMS
from lca.task import heightmap, observations, rewards, terminations
from lca.task.commands import gait_phase
from lca.task.config import TerminationConfig
from lca.task.rewards import compute_rewards
from lca.task.state import ContactAccumulator, RobotState, read_state
from lca.task.step_metrics import step_metrics
from tests.task.conftest import MIXED

STEPS = 12
# the tensors' device: cpu, and cuda where a GPU exists (.ci/gpu_check runs these there)
DEVICE = torch.device("cuda" if torch.cuda.is_available() else "cpu")
# float64 tensors must match NumPy to rounding; float32 (a GPU's dtype) to its precision
TOLERANCES = {
    torch.float64: dict(rtol=1e-10, atol=1e-12),
    torch.float32: dict(rtol=1e-4, atol=1e-5),
}


def to_torch(value, dtype: torch.dtype):
    """NumPy fields (nested dataclasses too) as torch tensors; floats as `dtype`."""
    if isinstance(value, np.ndarray):
        tensor = torch.from_numpy(np.array(value)).to(DEVICE)
        return tensor.to(dtype) if tensor.is_floating_point() else tensor
    if dataclasses.is_dataclass(value) and isinstance(value, RobotState):
        return RobotState(**{k: to_torch(v, dtype) for k, v in vars(value).items()})
    return value


def torch_copy(obj, dtype: torch.dtype):
    fields = {f.name: to_torch(getattr(obj, f.name), dtype) for f in dataclasses.fields(obj)}
    return dataclasses.replace(obj, **fields)


def close(torch_value: torch.Tensor, numpy_value: np.ndarray, dtype: torch.dtype) -> None:
    assert isinstance(torch_value, torch.Tensor) and torch_value.device.type == DEVICE.type
    np.testing.assert_allclose(torch_value.double().cpu().numpy(), numpy_value, **TOLERANCES[dtype])


@pytest.fixture(scope="module")
def stepped(make_env):
    """The env after a few random actions on the mixed terrain (contacts, swing, slips),
    with a third of the envs marked terminated."""
    cfg, env = make_env(*MIXED)
    env.reset_all()
    gen = torch.Generator().manual_seed(0)
    for _ in range(STEPS):
        env.step(torch.rand((env.num_envs, env.num_actions), generator=gen) * 2 - 1)
    terminated = np.arange(env.num_envs) % 3 == 0
    return env, env._reward_context(env.state, terminated)


@pytest.mark.parametrize("dtype", [torch.float64, torch.float32])
def test_every_reward_term_and_the_total_agree(stepped, dtype):
    env, ctx = stepped
    tctx = torch_copy(ctx, dtype)
    # the table's terms (a test elsewhere may register a NumPy-only plugin)
    names = [n for n in REWARD_TERMS.names() if REWARD_TERMS[n].__module__ == rewards.__name__]
    assert set(env.reward_manager.weights) <= set(names)
    for name in names:
        close(REWARD_TERMS[name](tctx), REWARD_TERMS[name](ctx), dtype)
    assert np.ptp(REWARD_TERMS["phase_contact"](ctx)) > 0  # contacts differ between envs
    shaping = dict(
        only_positive=True,
        penalty_scale=0.3,
        unclipped=frozenset({"feet_flat"}),
        boosts={"track_lin_vel_xy_exp": 2.0},
    )
    total, terms = compute_rewards(ctx, env.reward_manager.weights, env.dt, **shaping)
    ttotal, tterms = compute_rewards(tctx, env.reward_manager.weights, env.dt, **shaping)
    close(ttotal, total, dtype)
    for name, value in terms.items():
        close(tterms[name], value, dtype)


@pytest.mark.parametrize("dtype", [torch.float64, torch.float32])
def test_observation_groups_and_history_agree(stepped, dtype):
    env, ctx = stepped
    inputs = observations.ObsInputs(
        ctx.state, env.default_joint_pos, ctx.command, ctx.action, ctx.phase, ctx.standing
    )
    tinputs = torch_copy(inputs, dtype)
    for declared in (env.history_terms, env.current_terms):
        close(
            observations.build(tinputs, declared, None),
            observations.build(inputs, declared, None),
            dtype,
        )
    clean = observations.build(tinputs, env.history_terms, None)
    noisy = observations.build(tinputs, env.history_terms, torch.Generator(DEVICE).manual_seed(1))
    bound = np.concatenate(
        [np.full(t.dim, t.noise) * np.abs(np.asarray(t.scale)) for t in env.history_terms]
    )
    diff = (noisy - clean).abs().double().cpu().numpy()
    assert (diff <= bound * (1 + 1e-6) + 1e-6).all() and diff.max() > 0

    frames = [observations.build(inputs, env.history_terms, None) * k for k in (1, 2, 3)]
    numpy_h = observations.History(env.num_envs, 3, frames[0].shape[1])
    torch_h = observations.History(env.num_envs, 3, frames[0].shape[1], clean)
    ids = np.array([0, 5])
    for frame in frames:
        numpy_h.push(frame)
        torch_h.push(to_torch(frame, dtype))
    numpy_h.fill(ids, frames[0])
    torch_h.fill(to_torch(ids, dtype), to_torch(frames[0], dtype))
    close(torch_h.flat(), numpy_h.flat(), dtype)
    np.testing.assert_array_equal(numpy_h.buffer[1, 0], frames[2][1])  # newest first


def test_terminations_agree(stepped):
    env, ctx = stepped
    state = dataclasses.replace(ctx.state, joint_vel=np.array(ctx.state.joint_vel))
    state.joint_vel[1, 0] = np.nan
    state.joint_vel[2, 3] = 1e6
    state.base_pos = np.array(state.base_pos)
    state.base_pos[4, 2] = np.inf
    cfg = TerminationConfig(min_base_height=0.6, max_tilt=0.3)
    tstate = to_torch(state, torch.float64)
    for numpy_value, torch_value in (
        (terminations.fell(state, cfg), terminations.fell(tstate, cfg)),
        (terminations.non_finite(state, 1e3), terminations.non_finite(tstate, 1e3)),
    ):
        np.testing.assert_array_equal(torch_value.cpu().numpy(), numpy_value)
    assert terminations.non_finite(state, 1e3)[[1, 2, 4]].all()


@pytest.mark.parametrize("dtype", [torch.float64, torch.float32])
def test_step_metrics_agree(stepped, dtype):
    _, ctx = stepped
    time_out = np.arange(len(ctx.terminated)) % 4 == 1
    args = (ctx.state, ctx.command, ctx.terminated, time_out)
    metrics = step_metrics(*args, 100.0)
    tmetrics = step_metrics(*(to_torch(a, dtype) for a in args), 100.0)
    assert metrics.keys() == tmetrics.keys() and np.ptp(metrics["track_error"]) > 0
    for name, value in metrics.items():
        if value.dtype == bool:
            np.testing.assert_array_equal(tmetrics[name].cpu().numpy(), value)
        else:
            close(tmetrics[name], value, dtype)


@pytest.mark.parametrize("dtype", [torch.float64, torch.float32])
def test_height_query_and_maps_agree(stepped, dtype):
    env, ctx = stepped
    terrain = env.scene.terrain
    rng = np.random.default_rng(2)
    (x0, y0), (sx, sy) = terrain.origin, terrain.size
    # inside the grid, on its edge cells and beyond it (clamped)
    x = rng.uniform(x0 - 1.0, x0 + sx + 1.0, (64, 5))
    y = rng.uniform(y0 - 1.0, y0 + sy + 1.0, (64, 5))
    heights = terrain.height_at(x, y)
    assert np.ptp(heights) > 0.05  # stairs and blocks, not only flat ground
    tol = TOLERANCES[dtype] if dtype == torch.float64 else dict(rtol=0, atol=1e-4)
    got = terrain.height_at(to_torch(x, dtype), to_torch(y, dtype))
    np.testing.assert_allclose(got.double().cpu().numpy(), heights, **tol)

    xy, yaw = ctx.state.base_pos[:, :2], rng.uniform(-np.pi, np.pi, env.num_envs)
    sampled = heightmap.sample_heights(terrain, xy, yaw, env.critic_offsets)
    tsampled = heightmap.sample_heights(
        terrain, to_torch(xy, dtype), to_torch(yaw, dtype), env.critic_offsets
    )
    np.testing.assert_allclose(tsampled.double().cpu().numpy(), sampled, **tol)
    valid = rng.random(sampled.shape) > 0.3
    for mask in (None, valid):
        close(
            heightmap.normalise(tsampled, None if mask is None else to_torch(mask, dtype)),
            heightmap.normalise(tsampled.double().cpu().numpy(), mask),
            dtype,
        )


def test_gait_clock_agrees(stepped):
    env, _ = stepped
    period = env.task_cfg.reward_params.gait_period
    time = (env._episode_steps + np.arange(env.num_envs) * 7) * env.dt
    phase = gait_phase(time, period)
    assert phase.min() >= 0 and phase.max() < 1 and np.ptp(phase[:, 0]) > 0
    for dtype in TOLERANCES:
        close(gait_phase(to_torch(time, dtype), period), phase, dtype)


class TorchViews:
    """The sim's live arrays as torch tensors (zero-copy on the CPU, as `wp.to_torch` gives
    them for warp's arrays), for what the state reader uses."""

    def __init__(self, sim):
        self.sim, self.num_envs, self.scene = sim, sim.num_envs, sim.scene
        self.joint_qpos, self.joint_dof = sim.joint_qpos, sim.joint_dof

    def _view(self, array: np.ndarray) -> torch.Tensor:
        return torch.from_numpy(array).to(DEVICE)

    def sensor(self, name: str) -> torch.Tensor:
        return self._view(self.sim.sensor(name))

    def __getattr__(self, name: str) -> torch.Tensor:  # qpos, qvel, qacc, actuator_force
        return self._view(getattr(self.sim, name))


def test_state_and_contact_maxima_read_from_torch_views_agree(stepped):
    env, _ = stepped
    views = TorchViews(env.sim)
    contacts = ContactAccumulator(env.sim)
    tcontacts = ContactAccumulator(views)
    assert isinstance(tcontacts.foot_force, torch.Tensor)
    for _ in range(3):
        env.sim.step()
        contacts.update()
        if DEVICE.type == "cuda":  # copies, not views: the sensors as they are now
            tcontacts = replace_sensors(tcontacts, views)
        tcontacts.update()
    assert contacts.foot_force.max() > 0  # feet on the ground
    ids = np.array([1, 4, 6])
    for rows in (None, ids):
        state = read_state(env.sim, contacts, rows)
        tstate = read_state(views, tcontacts, None if rows is None else to_torch(rows, None))
        for name, value in vars(state).items():
            close(getattr(tstate, name), value, torch.float64)


def replace_sensors(contacts: ContactAccumulator, views: TorchViews) -> ContactAccumulator:
    fresh = ContactAccumulator(views)
    fresh.foot_force, fresh.foot_lateral = contacts.foot_force, contacts.foot_lateral
    fresh.leg_force = contacts.leg_force
    return fresh
