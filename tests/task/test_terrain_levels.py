"""The terrain-level curriculum (`terrain.levels`): a levelled grid, rows moved at resets."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
import torch

from lca.config import compose
from lca.evaluate.protocol import trial_config
from lca.sim.terrain import generate
from lca.task.env_state import env_state, restore_env_state
from lca.task.terrain_levels import TerrainLevels

LEVELLED = [
    "scale=smoke",
    "terrain=mixed",
    "terrain.levels=true",
    "terrain.rows=4",
    "terrain.cols=2",
    "terrain.mixture={flat: 0, stairs_up: 0.5, stairs_down: 0, uneven: 0.5}",
    "task.num_envs=8",
]


def test_levelled_grid_has_one_type_per_column_and_rises_row_by_row():
    cfg = compose(LEVELLED)
    terrain = generate(cfg.terrain, cfg.difficulty)
    by_cell = {(t.row, t.col): t for t in terrain.tiles}
    for col in range(2):
        column = [by_cell[(row, col)] for row in range(4)]
        assert len({t.kind for t in column}) == 1
        key = "riser" if column[0].kind == "stairs_up" else "high"
        heights = [t.params[key] for t in column]
        assert all(a < b for a, b in zip(heights, heights[1:], strict=False)), heights
    # the top row is the configured difficulty itself
    stairs = next(t for t in terrain.tiles if t.kind == "stairs_up" and t.row == 3)
    low, high = cfg.difficulty.stairs_riser
    assert low <= stairs.params["riser"] <= high
    first = next(t for t in terrain.tiles if t.kind == "stairs_up" and t.row == 0)
    assert first.params["riser"] <= high / 4


@pytest.fixture(scope="module")
def levelled(make_env):
    return make_env(*LEVELLED)


def _row_of(env, ids) -> np.ndarray:
    """Each env's row, read back from where it will spawn."""
    origin = np.asarray(env.sim.env_origin)[ids]
    return np.floor(origin[:, 1] / env.terrain_levels.tile_size).astype(int)


def _place(env, row: int) -> np.ndarray:
    """Every env on `row`; returns their spawn points."""
    env.terrain_levels.level[:] = row
    env.terrain_levels.place(np.arange(env.num_envs))
    return np.asarray(env.sim.env_origin).copy()


def test_envs_move_up_after_half_a_tile_and_down_after_too_little(levelled):
    _, env = levelled
    levels = env.terrain_levels
    half = levels.tile_size / 2
    xy = _place(env, 1)
    command = np.full((8, 2), [0.5, 0.0])
    xy[0:2, 0] += half + 0.1  # past half a tile: up, whatever the command
    xy[2:4, 0] += 0.05  # asked 0.5 m/s for a whole episode, barely moved: down
    xy[4:6, 1] += 0.75 * half  # under half a tile, but more than half of a slow command
    command[4:6] = [0.0, 0.75 * half / levels.episode_s]
    levels.update(np.arange(6), xy, command)
    assert list(levels.level) == [2, 2, 0, 0, 1, 1, 1, 1]
    assert list(_row_of(env, np.arange(8))) == [2, 2, 0, 0, 1, 1, 1, 1]
    # each env keeps its column; the spawn is the centre of its (row, column) tile
    origin = np.asarray(env.sim.env_origin)
    assert np.allclose(origin[:, 0], (np.arange(8) % 2 + 0.5) * levels.tile_size)


def test_envs_past_the_top_row_restart_on_a_random_row_and_row_zero_holds(levelled):
    _, env = levelled
    levels = env.terrain_levels
    rows = set()
    for _ in range(10):
        xy = _place(env, 3)
        xy[:, 0] += levels.tile_size  # walked a whole tile from the top row
        levels.update(np.arange(8), xy, np.zeros((8, 2)))
        rows |= set(levels.level.tolist())
    assert rows <= {0, 1, 2, 3} and len(rows) > 1
    standing = _place(env, 0)
    levels.update(np.arange(8), standing, np.full((8, 2), 0.5))  # fell at once: held at 0
    assert np.all(levels.level == 0)


def test_resets_move_rows_and_env_state_keeps_them(levelled):
    cfg, env = levelled
    levels = env.terrain_levels
    env.reset_all()
    env.sim.qpos[:, :2] = _place(env, 1)  # back at their spawns after 50 steps
    env._episode_steps[:] = 50
    env.commands.value[:, :2] = 0.5  # asked 5 m, stood: every env moves down on reset
    env._reset_envs(np.arange(8))
    assert np.all(levels.level == 0)
    assert 0.0 <= levels.mean() <= 1.0
    saved = env_state(env)
    _place(env, 3)
    restore_env_state(env, saved)
    assert np.all(levels.level == 0)
    assert np.all(_row_of(env, np.arange(8)) == 0)


def test_tests_run_without_levels():
    cfg = compose(LEVELLED)
    assert trial_config(cfg, 4, 5.0, [0.3, 0.6]).terrain.levels is False


def test_levels_run_on_torch_tensors():
    """The warp backend hands torch tensors: the same rules on them."""
    cfg = compose(LEVELLED)
    terrain = generate(cfg.terrain, cfg.difficulty)
    origin = torch.as_tensor(terrain.tile_centres()[np.arange(8) % 8], dtype=torch.float32)
    sim = SimpleNamespace(env_origin=origin, scene=SimpleNamespace(terrain=terrain))
    levels = TerrainLevels(sim, cfg.terrain, 20.0, torch.Generator().manual_seed(0))
    assert levels.level.dtype == torch.int64 and torch.all(levels.level == 0)
    xy = sim.env_origin.clone()
    xy[:4, 0] += cfg.terrain.tile_size  # walked a whole tile: up
    levels.update(torch.arange(8), xy, torch.full((8, 2), 0.5))  # others stood: held at 0
    assert levels.level.tolist() == [1, 1, 1, 1, 0, 0, 0, 0]
    assert torch.allclose(sim.env_origin[:4, 1], torch.tensor(1.5 * cfg.terrain.tile_size))


def test_turning_walker_moves_up_by_its_path_and_a_stuck_one_moves_down(levelled):
    """A walker on a circle ends near its spawn, and a commanded speed that changes mid-episode
    asks for its mean: the path walked and the mean command decide, not straight lines."""
    _, env = levelled
    levels = env.terrain_levels
    xy = _place(env, 1)
    dt, steps = 0.02, int(levels.episode_s / 0.02)
    radius, speed = 1.2, 0.4  # a 7.5 m circle walked in 18.8 s: ~one lap in the episode
    for k in range(1, steps + 1):
        t = k * dt
        angle = speed * t / radius
        pos = xy.copy()
        pos[0:4, 0] += radius * np.sin(angle)
        pos[0:4, 1] += radius * (1 - np.cos(angle))
        pos[4:8, 0] += 0.01 * np.sin(8 * t)  # stepping in place, swaying 1 cm
        command = np.full((8, 2), [speed, 0.0])
        command[:, 0] = speed if t < 10 else 0.1  # the last command is slow
        levels.track(pos, command, dt)
    assert np.linalg.norm(pos[0] - xy[0]) < levels.tile_size / 2  # straight line: not up
    levels.update(np.arange(8), pos, command)
    assert list(levels.level) == [2, 2, 2, 2, 0, 0, 0, 0]
    assert np.all(levels.path == 0) and np.all(levels.lived == 0)  # the next episode afresh


def test_when_the_curriculum_is_over_every_reset_goes_to_the_top_row(levelled):
    _, env = levelled
    levels = env.terrain_levels
    xy = _place(env, 1)
    levels.over = True
    levels.update(np.arange(8), xy, np.full((8, 2), 0.5))  # stood: would move down
    levels.over = False
    assert np.all(levels.level == 3) and np.all(_row_of(env, np.arange(8)) == 3)


def test_levels_end_must_be_a_fraction():
    with pytest.raises(ValueError, match="terrain.levels_end"):
        compose([*LEVELLED, "terrain.levels_end=1.5"])


def test_levels_from_zero_makes_row_zero_flat_and_rises_evenly_to_the_difficulty():
    cfg = compose([*LEVELLED, "terrain.levels_from=0"])
    terrain = generate(cfg.terrain, cfg.difficulty)
    stairs = sorted((t for t in terrain.tiles if t.kind == "stairs_up"), key=lambda t: t.row)
    risers = [t.params["riser"] for t in stairs]
    assert risers[0] == 0.0
    low, high = cfg.difficulty.stairs_riser
    assert low <= risers[-1] <= high
    # row r draws from [low, high] scaled by r / 3: each riser within its row's range
    for row, riser in enumerate(risers):
        assert low * row / 3 <= riser <= high * row / 3 + 1e-12, (row, risers)
    with pytest.raises(ValueError, match="terrain.levels_from"):
        compose([*LEVELLED, "terrain.levels_from=1.5"])
