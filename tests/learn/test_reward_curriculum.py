"""The reward curriculum: penalties start at a fraction, grow with the episode length, never
shrink, and are exactly the paper's from the deadline on; a real run ends on the paper's
objective and logs the scale, the learning rate and the KL."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
import torch

from lca.config import ConfigError
from lca.learn.command_curriculum import CommandCurriculum
from lca.learn.reward_curriculum import RewardCurriculum
from lca.task.commands import VelocityCommand
from lca.task.config import (
    CommandConfig,
    CommandCurriculumConfig,
    CommandRangesConfig,
    RewardCurriculumConfig,
)

from .helpers import make_trainer, read_curve, smoke_cfg

CFG = RewardCurriculumConfig(
    enabled=True, penalty_start=0.2, length_start=0.2, length_end=0.6, deadline=0.5
)


def test_scale_follows_episode_length_and_never_shrinks():
    c = RewardCurriculum(CFG, total_iterations=100)
    assert c.scale == 0.2
    assert c.update(0, float("nan")) == 0.2  # no finished episode yet
    assert c.update(1, 0.1) == 0.2
    assert c.update(2, 0.4) == pytest.approx(0.2 + 0.8 * 0.5)
    assert c.update(3, 0.05) == pytest.approx(0.6)  # shorter episodes do not lower it
    assert c.update(4, 0.6) == 1.0
    assert c.done


def test_scale_is_exactly_one_from_the_deadline_whatever_the_episodes():
    c = RewardCurriculum(CFG, total_iterations=10)
    scales = [c.update(it, 0.0) for it in range(10)]
    assert scales[:5] == [0.2] * 5
    assert scales[5:] == [1.0] * 5
    assert c.done and not c.only_positive


def test_hold_caps_the_length_ramp_then_releases_it_linearly_to_one():
    cfg = RewardCurriculumConfig(
        enabled=True,
        penalty_start=0.1,
        length_start=0.0,
        length_end=0.5,
        deadline=0.8,
        hold=0.6,
        hold_until=0.4,
    )
    c = RewardCurriculum(cfg, total_iterations=10)
    scales = [c.update(it, 1.0) for it in range(10)]  # episodes long from the start
    assert scales[:5] == [0.6] * 5  # held, however long the episodes
    assert scales[5:8] == pytest.approx([0.7, 0.8, 0.9])  # 0.6 -> 1 over iterations 4..8
    assert scales[8:] == [1.0, 1.0]  # exactly the paper's weights from the deadline
    assert c.done


def test_only_positive_is_an_early_stage_only():
    cfg = RewardCurriculumConfig(enabled=True, only_positive=True, deadline=0.5)
    c = RewardCurriculum(cfg, total_iterations=4)
    c.update(0, 0.0)
    assert c.only_positive and not c.done
    c.update(2, 0.0)
    assert not c.only_positive and c.done


def test_disabled_curriculum_is_the_paper_objective_from_the_start():
    c = RewardCurriculum(RewardCurriculumConfig(enabled=False), total_iterations=10)
    assert c.update(0, 0.0) == 1.0 and c.done


def test_training_run_ends_on_the_paper_objective(tmp_path, smoke_scene):
    cfg = smoke_cfg(
        "scale.max_iterations=4",
        "task.reward_curriculum.enabled=true",
        "task.reward_curriculum.penalty_start=0.3",
        "task.reward_curriculum.deadline=0.5",
    )
    trainer = make_trainer(cfg, tmp_path / "run", smoke_scene)
    trainer.train()
    rows = read_curve(tmp_path / "run" / "train_curve.csv")
    assert [float(r["penalty_scale"]) for r in rows] == [0.3, 0.3, 1.0, 1.0]
    assert trainer.env.reward_manager.penalty_scale == 1.0
    assert not trainer.env.reward_manager.only_positive
    assert all(float(r["learning_rate"]) > 0 for r in rows)
    assert all(np.isfinite(float(r["kl"])) for r in rows)  # the adaptive schedule's KL


FINAL_PHASE = (
    "scale.max_iterations=5",
    "task.reward_curriculum.enabled=true",
    "task.reward_curriculum.by=iterations",
    "algo.final_critic_warmup=1",
    "algo.final_learning_rate=2.0e-5",
)


def train_final_phase(path, scene, *overrides: str):
    """Five iterations with a final phase: the curve's rows, whether the actor moved at each
    update, and the trainer."""
    trainer = make_trainer(smoke_cfg(*FINAL_PHASE, *overrides), path, scene)
    actor = []
    trainer.train(
        hook=lambda t, it, row: actor.append(t.alg.actor.state_dict()["mlp.0.weight"].clone())
    )
    moved = [not torch.equal(a, b) for a, b in zip(actor, actor[1:], strict=False)]
    return read_curve(path / "train_curve.csv"), moved, trainer


@pytest.mark.slow  # trains: see README
def test_the_paper_phase_warms_the_critic_then_holds_a_low_rate(tmp_path, smoke_scene):
    """algo.final_*: from the cut (iteration 2 of 5) the critic trains alone for one
    iteration, then the actor too, at the fixed final learning rate."""
    rows, moved, trainer = train_final_phase(
        tmp_path / "run", smoke_scene, "task.reward_curriculum.cut=0.4"
    )
    assert [float(r["penalty_scale"]) < 1 for r in rows] == [True, True, False, False, False]
    assert [float(r["learning_rate"]) for r in rows][2:] == [2.0e-5] * 3
    assert float(rows[1]["learning_rate"]) != 2.0e-5
    assert moved == [True, False, True, True]  # iteration 2 trained the critic only
    assert trainer.alg.schedule == "fixed"


@pytest.mark.slow  # trains: see README
def test_the_last_phase_can_start_after_the_curriculum_ends(tmp_path, smoke_scene):
    """algo.final_from: the table's weights from iteration 1 (deadline 0.2 of 5), the
    critic alone at iteration 3 (final_from 0.6), then the fixed final rate."""
    rows, moved, _ = train_final_phase(
        tmp_path / "run",
        smoke_scene,
        "task.reward_curriculum.deadline=0.2",
        "algo.final_from=0.6",
    )
    assert [float(r["penalty_scale"]) for r in rows][1:] == [1.0] * 4
    rates = [float(r["learning_rate"]) for r in rows]
    assert rates[3:] == [2.0e-5] * 2 and 2.0e-5 not in rates[:3]
    assert moved == [True, True, False, True]  # iteration 3 trained the critic only


def test_final_from_names_its_key_when_out_of_range():
    with pytest.raises(Exception, match="algo.final_from"):
        smoke_cfg("algo.final_from=1.5")


def test_iteration_ramp_is_linear_to_the_deadline():
    cfg = RewardCurriculumConfig(enabled=True, penalty_start=0.2, by="iterations", deadline=0.5)
    c = RewardCurriculum(cfg, total_iterations=20)
    scales = [c.update(it, 1.0) for it in range(20)]  # episode length plays no part
    np.testing.assert_allclose(scales[:10], 0.2 + 0.8 * np.arange(10) / 10)
    assert scales[10:] == [1.0] * 10


def test_command_floor_falls_linearly_to_zero_at_the_deadline():
    cfg = CommandCurriculumConfig(enabled=True, min_speed=0.3, deadline=0.5)
    c = CommandCurriculum(cfg, total_iterations=20)
    floors = [c.floor(it) for it in range(20)]
    np.testing.assert_allclose(floors[:10], 0.3 * (1 - np.arange(10) / 10))
    assert floors[10:] == [0.0] * 10
    assert CommandCurriculum(CommandCurriculumConfig(), 20).floor(0) == 0.0


def test_command_ranges_widen_linearly_to_the_configured_ones():
    start = CommandRangesConfig(lin_vel_x=[0.3, 0.6], lin_vel_y=[0.0, 0.0], standing_fraction=0)
    cfg = CommandCurriculumConfig(enabled=True, min_speed=0.0, deadline=0.5, widen_from=start)
    target = CommandConfig()  # x in [-0.6, 0.6], y in [-0.3, 0.3], 10 % standing
    c = CommandCurriculum(cfg, total_iterations=20)
    assert c.ranges(0, target) == {
        "lin_vel_x": [0.3, 0.6],
        "lin_vel_y": [0.0, 0.0],
        "standing_fraction": 0.0,
    }
    half = c.ranges(5, target)
    np.testing.assert_allclose(half["lin_vel_x"], [-0.15, 0.6])
    np.testing.assert_allclose(half["lin_vel_y"], [-0.15, 0.15])
    assert half["standing_fraction"] == pytest.approx(0.05)
    assert "ang_vel_z" not in half  # not widened: the configured range throughout
    assert c.ranges(10, target) == {} and c.ranges(19, target) == {}


def test_commands_are_drawn_from_the_curriculum_ranges():
    commands = VelocityCommand(CommandConfig(), 4000, 0.02, np.random.default_rng(0))
    commands.ranges = {"lin_vel_x": [0.3, 0.6], "lin_vel_y": [0.0, 0.0], "standing_fraction": 0}
    commands.resample(np.arange(4000))
    u = commands.value
    assert u[:, 0].min() >= 0.3 and u[:, 0].max() <= 0.6 and not u[:, 1].any()
    assert np.abs(u[:, 2]).max() > 0.4  # yaw: still the configured +-0.5 rad/s
    commands.ranges = {}
    commands.resample(np.arange(4000))
    assert commands.value[:, 0].min() < -0.5 and commands.standing.mean() > 0.05


def test_widen_from_rejects_a_reversed_range():
    bad = CommandCurriculumConfig(widen_from=CommandRangesConfig(lin_vel_x=[0.6, 0.3]))
    with pytest.raises(ConfigError, match="widen_from.lin_vel_x"):
        bad.check()


def test_tracking_gate_steps_up_only_while_the_robot_tracks():
    cfg = RewardCurriculumConfig(
        enabled=True,
        penalty_start=0.2,
        by="tracking",
        gate=0.5,
        ramp=0.4,
        length_start=0.3,
        deadline=0.9,
    )
    c = RewardCurriculum(cfg, total_iterations=20)  # a full ramp: 8 gated steps of 0.1
    assert c.update(0, 0.9, 0.6) == pytest.approx(0.3)
    assert c.update(1, 0.9, 0.4) == pytest.approx(0.3)  # tracking below the gate: hold
    assert c.update(2, 0.2, 0.9) == pytest.approx(0.3)  # episodes too short: hold
    assert c.update(3, 0.9, float("nan")) == pytest.approx(0.3)
    for it in range(4, 11):
        c.update(it, 0.9, 0.8)
    assert c.scale == pytest.approx(1.0)
    late = RewardCurriculum(cfg, total_iterations=20)
    assert late.update(18, 0.0, 0.0) == 1.0  # the deadline, whatever the robot does


def test_boosts_fall_linearly_to_none_at_the_paper_weights():
    cfg = RewardCurriculumConfig(
        enabled=True, by="iterations", penalty_start=0.2, deadline=1.0, boost={"phase_contact": 4.0}
    )
    c = RewardCurriculum(cfg, total_iterations=100)
    c.update(0, 0.0)
    assert c.boosts == {"phase_contact": 4.0}
    c.update(50, 0.0)  # half way up the ramp: half the extra weight left
    assert c.scale == pytest.approx(0.6)
    assert c.boosts["phase_contact"] == pytest.approx(2.5)
    c.update(100, 0.0)
    assert c.done and c.boosts == {}  # the table's weights exactly
    assert c.shaping == (1.0, False, {}, 1.0)


def test_a_boost_multiplies_its_term_only():
    from types import SimpleNamespace

    from lca.task.rewards import compute_rewards

    ctx = SimpleNamespace(terminated=np.array([False, True]), command=np.zeros((2, 3)))
    weights = {"alive": 0.15, "termination_penalty": -200.0}
    plain, _ = compute_rewards(ctx, weights, dt=1.0)
    boosted, terms = compute_rewards(ctx, weights, dt=1.0, boosts={"alive": 3.0})
    np.testing.assert_allclose(terms["alive"], [0.45, 0.0])
    np.testing.assert_allclose(boosted - plain, [0.30, 0.0])


def tracking_boost(window: list[float], **extra) -> RewardCurriculumConfig:
    """Velocity tracking x3 over `window`; the penalties at the table's from half-way."""
    return RewardCurriculumConfig(
        enabled=True,
        by="iterations",
        deadline=0.5,
        boost={"track_lin_vel_xy_exp": 3.0},
        boost_window=window,
        **extra,
    )


def test_a_boost_window_applies_late_and_ends_on_the_paper_weights():
    c = RewardCurriculum(tracking_boost([0.6, 0.8]), total_iterations=100)
    c.update(10, 0.0)
    assert c.boosts == {} and not c.done  # the penalties still ramp; no boost before 60
    c.update(55, 0.0)
    assert c.done  # the table's weights between the deadline and the window
    c.update(60, 0.0)
    assert c.boosts == {"track_lin_vel_xy_exp": 3.0} and not c.done
    c.update(70, 0.0)
    assert c.boosts["track_lin_vel_xy_exp"] == pytest.approx(2.0)
    c.update(80, 0.0)
    assert c.done and c.shaping == (1.0, False, {}, 1.0)  # and so to the end
    c.update(99, 0.0)
    assert c.done


def test_a_narrow_tracking_sigma_widens_to_the_papers_with_the_boosts():
    c = RewardCurriculum(tracking_boost([0.0, 0.8], sigma_scale=0.2), total_iterations=100)
    c.update(0, 0.0)
    assert c.sigma_scale == pytest.approx(0.2)
    c.update(40, 0.0)
    assert c.sigma_scale == pytest.approx(0.6) and not c.done
    c.update(60, 0.0)  # penalties at the table's weights, the sigma still narrow
    assert c.scale == 1.0 and c.sigma_scale == pytest.approx(0.8) and not c.done
    c.update(80, 0.0)
    assert c.done and c.shaping == (1.0, False, {}, 1.0)


def test_a_narrow_sigma_pays_a_stall_far_less_than_a_walk():
    """Standing still against 0.45 m/s earns 44 % of the velocity kernel at the paper's
    sigma and 2 % at 0.2 x it; a walk 0.1 m/s short keeps most of it either way."""
    from types import SimpleNamespace

    from lca.task.config import RewardParams
    from lca.task.rewards import track_lin_vel_xy_exp

    command = np.array([[0.45, 0.0, 0.0], [0.45, 0.0, 0.0]])
    vel = np.array([[0.0, 0.0, 0.0], [0.35, 0.0, 0.0]])

    def kernel(sigma):
        ctx = SimpleNamespace(
            xp=np,
            command=command,
            state=SimpleNamespace(base_lin_vel=vel),
            params=RewardParams(tracking_sigma=sigma),
        )
        return track_lin_vel_xy_exp(ctx)

    stall, walk = kernel(0.25)
    assert stall == pytest.approx(0.44, abs=0.01) and walk > 0.95
    stall, walk = kernel(0.05)
    assert stall < 0.02 and walk > 0.8


def test_the_env_applies_the_sigma_scale(flat_cfg, flat_scene):
    from lca.task.env import LocomotionEnv

    env = LocomotionEnv(flat_cfg, scene=flat_scene)
    paper = env.task_cfg.reward_params.tracking_sigma
    env.reward_manager.set_shaping(1.0, False, {}, 0.2)
    assert env.reward_manager.params.tracking_sigma == pytest.approx(0.2 * paper)
    assert env.task_cfg.reward_params.tracking_sigma == paper  # the config is untouched
    env.reward_manager.set_shaping(1.0, False, {}, 1.0)
    assert env.reward_manager.params.tracking_sigma == pytest.approx(paper)


def test_a_cut_ends_every_shaping_at_once():
    """R8's schedule cut at 64 %: the ramp, the clip, the boost and the narrow sigma are as
    without the cut until then, and the paper's objective from the cut on."""
    cfg = replace(tracking_boost([0.0, 0.85], sigma_scale=0.2), deadline=0.85, only_positive=True)
    cut = RewardCurriculum(replace(cfg, cut=0.64), total_iterations=100)
    uncut = RewardCurriculum(cfg, total_iterations=100)
    for it in range(64):
        assert cut.update(it, 0.0) == uncut.update(it, 0.0)
        assert cut.shaping == uncut.shaping and not cut.done
    assert cut.end == 64 and uncut.end == 85
    for it in (64, 70, 99):
        cut.update(it, 0.0)
        assert cut.done and cut.shaping == (1.0, False, {}, 1.0)


def test_a_term_window_opening_at_the_cut_boosts_that_term_after_it():
    """The G1 transition (reports/learning.md): the tracking boost ends at the cut, and the
    fall's cost, x5 from the cut, falls linearly to the table's at 0.9."""
    cfg = replace(
        tracking_boost([0.0, 0.85], sigma_scale=0.2),
        cut=0.6,
        boost={"track_lin_vel_xy_exp": 3.0, "termination_penalty": 5.0},
        boost_windows={"termination_penalty": [0.6, 0.9]},
    )
    cfg.check()
    c = RewardCurriculum(cfg, total_iterations=100)
    c.update(30, 0.0)
    assert set(c.boosts) == {"track_lin_vel_xy_exp"} and c.sigma_scale < 1
    c.update(60, 0.0)
    assert c.boosts == {"termination_penalty": 5.0} and c.sigma_scale == 1.0
    assert c.scale == 1.0 and not c.only_positive and not c.done
    c.update(75, 0.0)
    assert c.boosts["termination_penalty"] == pytest.approx(3.0)
    c.update(90, 0.0)
    assert c.done and c.shaping == (1.0, False, {}, 1.0)


def test_a_term_window_needs_its_boost():
    cfg = RewardCurriculumConfig(enabled=True, boost_windows={"termination_penalty": [0.6, 0.9]})
    with pytest.raises(ValueError, match="boost_windows.termination_penalty"):
        cfg.check()


@pytest.mark.parametrize("value", [0.0, 1.2])
def test_a_cut_must_be_a_fraction_of_the_run(value):
    with pytest.raises(ValueError, match="cut"):
        RewardCurriculumConfig(enabled=True, cut=value).check()


def test_sigma_scale_must_be_positive():
    with pytest.raises(ValueError, match="sigma_scale"):
        RewardCurriculumConfig(enabled=True, sigma_scale=0.0).check()


@pytest.mark.parametrize("window", [[0.5], [0.8, 0.6], [0.6, 1.0], [-0.1, 0.5]])
def test_a_boost_window_must_end_before_the_run(window):
    cfg = RewardCurriculumConfig(enabled=True, boost_window=window)
    with pytest.raises(ValueError, match="boost_window"):
        cfg.check()


@pytest.mark.parametrize("iterations", [30, 2450])
def test_the_default_recipe_ends_on_the_paper_objective(iterations):
    """scale=cpu's curricula (the walk recipe): every device has ended before the run does,
    and from then on the env gets the table's weights, unclipped, unboosted."""
    from omegaconf import OmegaConf

    from lca.config import compose

    task = OmegaConf.to_object(compose([f"scale.max_iterations={iterations}"]).task)
    rewards = RewardCurriculum(task.reward_curriculum, iterations)
    commands = CommandCurriculum(task.command_curriculum, iterations)
    shaping = []
    for it in range(iterations):
        rewards.update(it, 0.0)
        shaping.append((rewards.shaping, rewards.done, commands.ranges(it, task.commands)))
    assert shaping[0][1] is False and any(s[0][2] for s in shaping)  # devices were on
    end = int(0.9 * iterations)
    assert all(s == ((1.0, False, {}, 1.0), True, {}) for s in shaping[end:])
