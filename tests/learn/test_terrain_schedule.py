"""The trainer's terrain switches: the practice shares end at `terrain.practice_end`, and
`terrain.after_levels: full_grid` rebuilds the terrain without levels at `levels_end`."""

from __future__ import annotations

import numpy as np
import pytest

from lca.config import ConfigError
from lca.learn.trainer import Trainer
from lca.store import RunDir

from .helpers import make_trainer, read_curve, smoke_cfg


@pytest.mark.slow  # trains: see README
@pytest.mark.parametrize("start, practised", [(0.0, [1, 1, 0, 0]), (0.25, [0, 1, 0, 0])])
def test_practice_holds_between_its_fractions_of_the_run(
    tmp_path, smoke_scene, start, practised
) -> None:
    cfg = smoke_cfg(
        "scale.max_iterations=4",
        "+terrain.practice={stairs_up: 0.5, uneven: 0.5}",
        f"terrain.practice_start={start}",
        "terrain.practice_end=0.5",
    )
    trainer = make_trainer(cfg, tmp_path / "run", smoke_scene)
    on = []
    trainer.train(hook=lambda t, it, row: on.append(t.env.terrain_practice.on))
    assert on == [bool(p) for p in practised]
    centres = smoke_scene.terrain.tile_centres()
    spread = centres[np.arange(trainer.env.num_envs) % len(centres)]
    np.testing.assert_allclose(np.asarray(trainer.env.sim.env_origin), spread)


FULL_GRID = (
    "scale.max_iterations=4",
    "scale.checkpoint_interval=1",
    "terrain.levels=true",
    "terrain.rows=2",
    "terrain.cols=2",
    "terrain.mixture={flat: 0, stairs_up: 0.5, stairs_down: 0, uneven: 0.5}",
    "terrain.levels_end=0.5",
    "terrain.after_levels=full_grid",
)
TRAINED = ("mean_reward", "mean_episode_length", "value_loss", "surrogate_loss", "action_std")


@pytest.mark.slow  # trains: see README
@pytest.mark.parametrize("killed_after", [1, 2])
def test_the_full_grid_follows_the_levels_and_resumes_exactly(tmp_path, killed_after) -> None:
    """`after_levels: full_grid` rebuilds the terrain without levels at `levels_end`; a run
    killed before or after the rebuild resumes onto the right terrain and trains on as the
    uninterrupted run did."""
    levelled = []
    straight = Trainer(smoke_cfg(*FULL_GRID), RunDir(tmp_path / "straight"))
    straight.train(hook=lambda t, it, row: levelled.append(t.env.terrain_levels is not None))
    assert levelled == [True, True, False, False]
    kinds = {tile.kind for tile in straight.env.scene.terrain.tiles}
    assert kinds == {"stairs_up", "uneven"} and not straight.env.cfg.terrain.levels
    curve = read_curve(tmp_path / "straight" / "train_curve.csv")
    assert [r["terrain_level"] != "nan" for r in curve] == [True, True, False, False]

    first = Trainer(smoke_cfg(*FULL_GRID), RunDir(tmp_path / "resumed"))
    first.train(hook=lambda t, it, row: it == killed_after)
    resumed = Trainer(smoke_cfg(*FULL_GRID), RunDir(tmp_path / "resumed"))
    assert resumed.start == killed_after + 1
    # the env of the saved iteration: the full grid once the rebuild was behind it
    assert (resumed.env.terrain_levels is None) == (killed_after >= 2)
    resumed.train()
    again = read_curve(tmp_path / "resumed" / "train_curve.csv")
    for a, b in zip(curve, again, strict=True):
        assert {k: a[k] for k in TRAINED} == {k: b[k] for k in TRAINED}, a["iteration"]


def test_after_levels_names_its_allowed_values() -> None:
    with pytest.raises(ConfigError, match=r"terrain.after_levels.*allowed.*full_grid"):
        smoke_cfg("terrain.after_levels=grid")
