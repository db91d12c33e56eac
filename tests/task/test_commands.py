"""Velocity commands and the gait clock."""

from __future__ import annotations

import numpy as np
import pytest

from lca.task.commands import VelocityCommand, gait_phase
from lca.task.config import CommandConfig


def test_gait_phase_left_and_right_half_a_period_apart():
    t = np.array([0.0, 0.2, 0.6, 0.8, 1.0])
    phase = gait_phase(t, 0.8)
    np.testing.assert_allclose(phase[:, 0], [0.0, 0.25, 0.75, 0.0, 0.25], atol=1e-12)
    np.testing.assert_allclose(phase[:, 1], [0.5, 0.75, 0.25, 0.5, 0.75], atol=1e-12)
    assert ((phase >= 0) & (phase < 1)).all()


def test_resample_ranges_and_standing_share():
    cfg = CommandConfig()
    n = 20000
    cmd = VelocityCommand(cfg, n, dt=0.02, rng=np.random.default_rng(0))
    cmd.resample(np.arange(n))
    v = cmd.value
    for k, (lo, hi) in enumerate([cfg.lin_vel_x, cfg.lin_vel_y, cfg.ang_vel_z]):
        assert v[:, k].min() >= lo and v[:, k].max() <= hi
    zero = (v == 0).all(axis=1)
    assert zero.mean() == pytest.approx(cfg.standing_fraction, abs=0.01)
    np.testing.assert_array_equal(cmd.standing, np.linalg.norm(v, axis=1) < 5e-3)
    assert cmd.standing[zero].all()
    np.testing.assert_allclose(cmd.time_left, cfg.resample_time_s)


def test_resample_only_touches_the_given_envs():
    cmd = VelocityCommand(CommandConfig(standing_fraction=0.0), 4, 0.02, np.random.default_rng(1))
    cmd.resample(np.array([1, 3]))
    assert (cmd.value[[0, 2]] == 0).all()
    assert (cmd.value[[1, 3]] != 0).all()
    assert not cmd.standing[[1, 3]].any() and cmd.standing[[0, 2]].all()
    cmd.resample(np.array([], dtype=int))  # no-op


def test_update_resamples_after_the_resample_time():
    cfg = CommandConfig(resample_time_s=0.1, standing_fraction=0.0)
    cmd = VelocityCommand(cfg, 2, dt=0.02, rng=np.random.default_rng(2))
    cmd.resample(np.arange(2))
    first = cmd.value.copy()
    for _ in range(4):  # 0.08 s
        cmd.update()
    np.testing.assert_array_equal(cmd.value, first)
    for _ in range(2):  # 0.10 s (+ one step of float round-off)
        cmd.update()
    assert (cmd.value != first).all()


def test_speed_floor_scales_slow_commands_up_and_keeps_their_direction():
    cfg = CommandConfig()
    n = 20000
    free = VelocityCommand(cfg, n, dt=0.02, rng=np.random.default_rng(1))
    floored = VelocityCommand(cfg, n, dt=0.02, rng=np.random.default_rng(1))
    floored.min_speed = 0.3
    free.resample(np.arange(n))
    floored.resample(np.arange(n))
    moving = ~floored.standing
    speed = np.linalg.norm(floored.value[:, :2], axis=1)
    assert speed[moving].min() >= 0.3 - 1e-12
    # the same draws: fast commands untouched, slow ones stretched along their direction
    fast = np.linalg.norm(free.value[:, :2], axis=1) >= 0.3
    np.testing.assert_array_equal(floored.value[fast], free.value[fast])
    slow = moving & ~fast & (np.linalg.norm(free.value[:, :2], axis=1) > 0)
    assert slow.sum() > 1000
    cross = np.cross(floored.value[slow, :2], free.value[slow, :2])
    np.testing.assert_allclose(cross, 0.0, atol=1e-12)
    np.testing.assert_array_equal(floored.value[:, 2], free.value[:, 2])  # yaw rates kept
    assert floored.standing.mean() == pytest.approx(cfg.standing_fraction, abs=0.01)


def test_commands_on_torch_tensors_follow_the_same_rules():
    """sim.backend=warp keeps the commands on the physics device: torch buffers drawn from a
    torch.Generator, with the same ranges, standing share, floor and resample clock."""
    torch = pytest.importorskip("torch")
    device = torch.device("cuda" if torch.cuda.is_available() else "cpu")
    cfg = CommandConfig(resample_time_s=0.1)
    n = 20000
    gen = torch.Generator(device).manual_seed(0)
    ref = torch.zeros(0, dtype=torch.float32, device=device)
    cmd = VelocityCommand(cfg, n, dt=0.02, rng=gen, reference=ref)
    cmd.min_speed = 0.3
    cmd.resample(torch.arange(n, device=device))
    v = cmd.value
    assert isinstance(v, torch.Tensor) and v.dtype == torch.float32 and v.device == device
    for k, (lo, hi) in enumerate([cfg.lin_vel_x, cfg.lin_vel_y, cfg.ang_vel_z]):
        assert lo <= v[:, k].min() and v[:, k].max() <= hi
    zero = (v == 0).all(dim=1)
    assert zero.float().mean().item() == pytest.approx(cfg.standing_fraction, abs=0.01)
    assert torch.equal(cmd.standing, torch.linalg.vector_norm(v, dim=1) < cfg.standing_epsilon)
    assert torch.linalg.vector_norm(v[~zero, :2], dim=1).min() >= 0.3 - 1e-6  # the floor
    first = v.clone()
    for _ in range(4):  # 0.08 s: nothing due
        cmd.update()
    assert torch.equal(cmd.value, first)
    for _ in range(2):  # 0.10 s: every command drawn again
        cmd.update()
    assert (cmd.value != first).any(dim=1).float().mean() > 0.95
