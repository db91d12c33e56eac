"""Departures from the paper are derived from the config against the paper profile."""

from __future__ import annotations

from lca.config import compose
from lca.departures import departures


def test_paper_profile_departs_nowhere() -> None:
    assert departures(compose(["scale=paper", "encoder.pool=0"])) == []


def test_every_changed_training_setting_is_listed_with_both_values() -> None:
    cfg = compose(
        [
            "policy=blind",
            "terrain=flat",
            "algo.symmetry=true",
            "robot.collision_parts=[feet,legs]",
            "seed=3",
            "eval.units=7",
        ]
    )
    found = departures(cfg)
    text = "\n".join(found)
    assert "algo.symmetry=True (paper: False)" in found
    assert (
        "robot.collision_parts=['feet', 'legs'] (paper: ['feet', 'legs', 'torso', 'arms'])" in found
    )
    assert "algo.num_learning_epochs=2 (paper: 5)" in found  # scale=cpu's
    assert "task.num_envs=256 (paper: 4096)" in found
    mixture = "terrain.mixture={flat: 1} (paper: {flat: 0.25"
    assert any(line.startswith(mixture) for line in found), text
    assert "task.reward_curriculum.enabled=True (paper: False)" in found
    # the study's axes and bookkeeping are not departures
    assert not any(line.startswith(("seed", "eval.", "actor.name", "scale.name")) for line in found)


def test_derived_inside_a_running_hydra_app() -> None:
    """run.py's job writes its provenance inside `@hydra.main`: the paper profile still
    composes there, and the app's global Hydra is left as it was."""
    from hydra import initialize_config_dir
    from hydra.core.global_hydra import GlobalHydra

    from lca.paths import conf_dir

    with initialize_config_dir(config_dir=str(conf_dir()), version_base="1.3"):
        app = GlobalHydra.instance().hydra
        found = departures(compose(["policy=blind", "scale=reference"]))
        assert GlobalHydra.instance().hydra is app
    assert not any(line.startswith("not derived") for line in found), found
    assert "algo.init_map_zero=True (paper: False)" in found
