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
        (["task.reward_curriculum.unclipped=[joy]"], "task.reward_curriculum.unclipped"),
        (["actor.final_noise_std=2.0"], "actor.final_noise_std"),
        (["terrain.apron=-1"], "terrain.apron"),
        # one row per remaining check of the groups (lca/<layer>/config.py)
        (["sim.timestep=0"], "sim.timestep"),
        (["sim.decimation=0"], "sim.decimation"),
        (["sim.integrator=verlet"], "sim.integrator"),
        (["sim.cone=round"], "sim.cone"),
        (["sim.iterations=0"], "sim.iterations"),
        (["robot.collision_parts=[feet,tail]"], "robot.collision_parts"),
        (["robot.natural_frequency_hz=0"], "robot.natural_frequency_hz"),
        (["robot.damping_ratio=-1"], "robot.damping_ratio"),
        (["+robot.stiffness.knee=-5"], "robot.stiffness.knee"),
        (["robot.actuators.m4010.effort_limit=0"], "robot.actuators.m4010.effort_limit"),
        (["terrain.rows=0"], "terrain.rows/cols"),
        (["terrain.resolution=0"], "terrain.resolution"),
        (["terrain.platform=9.0"], "terrain.platform"),
        (["terrain.num_steps=0"], "terrain.num_steps"),
        (["+terrain.mixture.lava=1.0", "terrain=flat"], "terrain.mixture.lava"),
        (["difficulty.height_noise=-0.1"], "difficulty.height_noise"),
        (["task.randomization.friction=[1.2,0.6]"], "task.randomization.friction"),
        (["task.randomization.added_base_mass=[3,-1]"], "task.randomization.added_base_mass"),
        (["task.observations.history=0"], "task.observations.history"),
        (["task.observations.height_dropout=1.0"], "task.observations.height_dropout"),
        (["task.observations.current.0.name=heart_rate"], "task.observations.current[0].name"),
        (
            ["task.observations.proprioception.1.noise=-1"],
            "task.observations.proprioception[1].noise",
        ),
        (["task.observations.current.0.clip=0"], "task.observations.current[0].clip"),
        (["task.commands.lin_vel_x=[0.6,-0.6]"], "task.commands.lin_vel_x"),
        (["task.commands.standing_fraction=1.5"], "task.commands.standing_fraction"),
        (["task.rewards.alive=abc"], "task.rewards.alive"),
        (["task.rewards.alive={weight: 1, scale: 2}"], "task.rewards.alive"),
        (["+task.rewards.joy=1.0"], "task.rewards.joy"),
        (["task.reward_curriculum.penalty_start=1.5"], "task.reward_curriculum.penalty_start"),
        (
            ["task.reward_curriculum.length_start=0.9"],
            "task.reward_curriculum.length_start/length_end",
        ),
        (["task.reward_curriculum.deadline=2"], "task.reward_curriculum.deadline"),
        (["task.reward_curriculum.ramp=0"], "task.reward_curriculum.ramp"),
        (["task.reward_curriculum.hold=0"], "task.reward_curriculum.hold"),
        (
            ["task.reward_curriculum.hold=0.5", "task.reward_curriculum.hold_until=0.9"],
            "task.reward_curriculum.hold_until",
        ),
        (["task.command_curriculum.min_speed=-1"], "task.command_curriculum.min_speed"),
        (["perception.source=lidar"], "perception.source"),
        (["perception.source=deployment", "perception.cameras=[]"], "perception.cameras"),
        (["hardware.tasks=[ladder]"], "hardware.tasks"),
        (["hardware.trials=0"], "hardware.trials"),
        (["actor.kind=gru"], "actor.kind"),
        (["actor.init_noise_std=0"], "actor.init_noise_std"),
        (["actor.noise_deadline=1.5"], "actor.noise_deadline"),
        (["actor.final_noise_std=0.3", "actor.noise_start=0.9"], "actor.noise_start"),
        (["actor.noise_by=mood"], "actor.noise_by"),
        (["encoder.kind=transformer"], "encoder.kind"),
        (["encoder.pool=4"], "encoder.pool"),
        (["curriculum.perception_from=1.5"], "curriculum.perception_from"),
        (["algo.lam=1.5"], "algo.lam"),
        (["algo.num_learning_epochs=0"], "algo.num_learning_epochs"),
        (["eval.units=0"], "eval.units"),
        (["eval.video_seconds=0"], "eval.video_seconds"),
        (["eval.cells=[{terrain: lava, difficulty: hard}]"], "eval.cells[0].terrain"),
        (["eval.cells=[{terrain: flat, difficulty: easy}]"], "eval.cells[0].difficulty"),
        (["eval.command_x=[0.6,0.3]"], "eval.command_x"),
        (["logger.name=stdout"], "logger.name"),
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


@pytest.mark.parametrize(
    "override", ["+task.typo_key=1", "+task.reward_params.sigma=1", "+seeds=1", "+eval.cell=x"]
)
def test_an_appended_key_outside_the_schema_fails_at_composition(override: str) -> None:
    key = override[1:].split("=")[0]
    with pytest.raises(ConfigError, match=rf"^{key}: not in the schema"):
        compose([override])
