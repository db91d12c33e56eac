"""Practice shares (`terrain.practice`): which tile each env respawns on until practice_end."""

from __future__ import annotations

import numpy as np
import pytest

from lca.config import compose
from lca.config.errors import ConfigValueError
from lca.evaluate.protocol import trial_config
from lca.task.terrain_practice import spread

KINDS = ["stairs_down", "flat", "stairs_up", "uneven", "stairs_up", "flat"]
ALL_PITS, END = "+terrain.practice={stairs_up: 1.0}", "terrain.practice_end"
PITS = {"flat": 0.25, "stairs_up": 0.5, "stairs_down": 0.125, "uneven": 0.125}
GRID = ["scale=smoke", "terrain=mixed", "terrain.rows=2", "terrain.cols=4", "task.num_envs=16"]


def test_even_spread_is_env_i_on_tile_i():
    assert list(spread(KINDS, 8)) == [0, 1, 2, 3, 4, 5, 0, 1]


def test_shares_set_each_kinds_env_count_and_cycle_over_its_tiles():
    tiles = spread(KINDS, 16, PITS)
    kinds = [KINDS[t] for t in tiles]
    assert {k: kinds.count(k) for k in PITS} == {k: int(16 * w) for k, w in PITS.items()}
    # each kind's envs alternate between its tiles
    pits = [t for t in tiles if KINDS[t] == "stairs_up"]
    assert pits == [2, 4] * 4
    # kinds interleave: the first half of the envs already holds every kind
    assert set(kinds[:8]) == set(PITS)


def test_a_kind_with_no_share_gets_no_env():
    tiles = spread(KINDS, 10, {"flat": 0.5, "stairs_up": 0.5, "uneven": 0.0})
    assert sorted({KINDS[t] for t in tiles}) == ["flat", "stairs_up"]


@pytest.mark.parametrize(
    "overrides, key",
    [
        (["+terrain.practice={ledge: 1.0}", "terrain.practice_end=0.5"], "terrain.practice.ledge"),
        (["+terrain.practice={stairs_up: 0.6}", "terrain.practice_end=0.5"], "terrain.practice"),
        ([ALL_PITS], END),
        ([ALL_PITS, f"{END}=1.5"], END),
        (["terrain.practice_end=0.5"], "terrain.practice"),
        ([ALL_PITS, f"{END}=0.5", "terrain.practice_start=0.5"], "terrain.practice_start"),
    ],
)
def test_bad_practice_names_its_key(overrides, key):
    with pytest.raises(ConfigValueError, match=f"^{key}:"):
        compose(["terrain=mixed", *overrides])


def _kinds_at_spawn(env) -> list[str]:
    """The kind of the tile each env will respawn on."""
    terrain = env.sim.scene.terrain
    origin = np.asarray(env.sim.env_origin)[:, :2]
    centres = terrain.tile_centres()[:, :2]
    nearest = np.argmin(np.linalg.norm(origin[:, None] - centres[None], axis=2), axis=1)
    return [terrain.tiles[i].kind for i in nearest]


@pytest.mark.parametrize("levels", [False, True])
def test_env_spawns_by_shares_until_switched_off(make_env, levels):
    share = "{stairs_up: 0.5, flat: 0.25, uneven: 0.25}"
    _, env = make_env(
        *GRID,
        f"terrain.levels={str(levels).lower()}",
        f"+terrain.practice={share}",
        "terrain.practice_end=0.5",
    )
    kinds = _kinds_at_spawn(env)
    assert kinds.count("stairs_up") == 8 and kinds.count("stairs_down") == 0
    env.terrain_practice.set(False)
    if levels:
        env.terrain_levels.place(np.arange(env.num_envs))  # what a reset does
    kinds = _kinds_at_spawn(env)
    assert {k: kinds.count(k) for k in set(kinds)} == dict.fromkeys(PITS, 4)


def test_evaluation_spreads_units_evenly():
    cfg = compose(["terrain=mixed", ALL_PITS, f"{END}=0.5"])
    trial = trial_config(cfg, 4, 5.0, [0.3, 0.6])
    assert dict(trial.terrain.practice) == {} and trial.terrain.practice_end == 0.0
