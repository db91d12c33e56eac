"""Composition: the paper's values, and bad configs failing at composition naming the key."""

from __future__ import annotations

import pytest
from hydra.errors import ConfigCompositionException, MissingConfigException

from lca.config import ConfigError, compose


def test_default_composes() -> None:
    cfg = compose()
    assert cfg.terrain.name == "mixed" and cfg.difficulty.name == "medium"
    assert sum(cfg.terrain.mixture.values()) == pytest.approx(1.0)


@pytest.mark.parametrize(
    ("name", "riser", "tread", "uneven", "noise"),
    [
        ("medium", [0.14, 0.18], 0.31, [0.05, 0.20], 0.10),
        ("hard", [0.16, 0.20], 0.23, [0.05, 0.40], 0.30),
    ],
)
def test_difficulty_table_matches_paper(name, riser, tread, uneven, noise) -> None:
    d = compose([f"difficulty={name}"]).difficulty
    assert list(d.stairs_riser) == pytest.approx(riser)
    assert d.stairs_tread == pytest.approx(tread)
    assert list(d.uneven_height) == pytest.approx(uneven)
    assert d.height_noise == pytest.approx(noise)


def test_unknown_terrain_option() -> None:
    with pytest.raises(MissingConfigException) as err:
        compose(["terrain=lava"])
    message = str(err.value)
    assert "terrain/lava" in message
    for option in ("flat", "mixed", "stairs_up", "stairs_down", "uneven"):
        assert option in message


@pytest.mark.parametrize(
    "override",
    [
        "terrain.mixture.lava=0.5",
        # Hydra's own error for the line above suggests this form; it must fail too.
        "+terrain.mixture.lava=0.5",
    ],
)
def test_unknown_terrain_type_in_mixture(override: str) -> None:
    with pytest.raises((ConfigCompositionException, ConfigError)) as err:
        compose([override])
    chain = f"{err.value} {err.value.__cause__}"
    assert "terrain.mixture" in chain and "lava" in chain


@pytest.mark.parametrize(
    ("overrides", "key"),
    [
        (["difficulty.stairs_riser=[-0.1,0.2]"], "difficulty.stairs_riser"),
        (["difficulty.stairs_riser=[0.2,0.1]"], "difficulty.stairs_riser"),
        (["difficulty.uneven_height=[-0.05,0.2]"], "difficulty.uneven_height"),
        (["difficulty.stairs_tread=0"], "difficulty.stairs_tread"),
        (["terrain.mixture.flat=0.5"], "terrain.mixture"),
        (["terrain=flat", "terrain.mixture.flat=0.5"], "terrain.mixture"),
        (["terrain.mixture.uneven=-0.25", "terrain.mixture.flat=0.75"], "terrain.mixture"),
        (["terrain.resolution=0.03"], "terrain.tile_size"),
        (["algo.learning_rate=-1"], "algo.learning_rate"),
        (["algo.gamma=1.5"], "algo.gamma"),
        (["algo.num_mini_batches=0"], "algo.num_mini_batches"),
        (["algo.entropy_coef=-0.1"], "algo.entropy_coef"),
        (["algo.schedule=cosine"], "algo.schedule"),
        (["scale.max_iterations=0"], "scale.max_iterations"),
        (["scale.log_interval=0"], "scale.log_interval"),
        (["scale.checkpoint_interval=0"], "scale.checkpoint_interval"),
        (["task.num_envs=-5"], "task.num_envs"),
        (["task.reward_curriculum.by=vibes"], "task.reward_curriculum.by"),
        (["task.reward_curriculum.terms=[joy]"], "task.reward_curriculum.terms"),
        (["actor.final_noise_std=2.0"], "actor.final_noise_std"),
        (["terrain.apron=-1"], "terrain.apron"),
    ],
)
def test_bad_values_name_the_key(overrides: list[str], key: str) -> None:
    with pytest.raises(ConfigError) as err:
        compose(overrides)
    assert isinstance(err.value, ValueError)
    assert str(err.value).startswith(f"{key}:"), str(err.value)


def test_mixture_weights_message_is_informative() -> None:
    with pytest.raises(ConfigError, match=r"^terrain\.mixture: weights must sum to 1"):
        compose(["terrain=mixed", "terrain.mixture.flat=0.5"])


def test_dead_key_scale_num_envs_is_gone() -> None:
    """The number of environments is `task.num_envs`; `scale.num_envs` was never read."""
    with pytest.raises((ConfigCompositionException, ConfigError)) as err:
        compose(["scale.num_envs=-5"])
    assert "scale.num_envs" in str(err.value)
