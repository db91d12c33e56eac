"""The trainer's terrain switches: the practice shares end at `terrain.practice_end`."""

from __future__ import annotations

import numpy as np
import pytest

from .helpers import make_trainer, smoke_cfg


@pytest.mark.slow  # trains: see README
def test_practice_ends_at_its_fraction_of_the_run(tmp_path, smoke_scene) -> None:
    cfg = smoke_cfg(
        "scale.max_iterations=4",
        "+terrain.practice={stairs_up: 0.5, uneven: 0.5}",
        "terrain.practice_end=0.5",
    )
    trainer = make_trainer(cfg, tmp_path / "run", smoke_scene)
    on = []
    trainer.train(hook=lambda t, it, row: on.append(t.env.terrain_practice.on))
    assert on == [True, True, False, False]
    centres = smoke_scene.terrain.tile_centres()
    spread = centres[np.arange(trainer.env.num_envs) % len(centres)]
    np.testing.assert_allclose(np.asarray(trainer.env.sim.env_origin), spread)
