"""The exploration schedule: a ceiling on the action std that falls linearly, then holds."""

from __future__ import annotations

import numpy as np
import pytest

from lca.learn.config import ActorConfig
from lca.learn.exploration import noise_ceiling

from .helpers import make_trainer, read_curve, smoke_cfg

pytestmark = pytest.mark.slow  # trains, evaluates or runs a stage: see README


def test_ceiling_falls_linearly_to_the_final_std_and_holds():
    cfg = ActorConfig(init_noise_std=1.0, final_noise_std=0.4, noise_deadline=0.5)
    ceilings = [noise_ceiling(cfg, it, 20) for it in range(20)]
    np.testing.assert_allclose(ceilings[:11], 1.0 - 0.6 * np.arange(11) / 10)
    assert ceilings[10:] == pytest.approx([0.4] * 10)
    assert noise_ceiling(ActorConfig(), 5, 20) is None  # off by default: rsl-rl's free std


def test_ceiling_holds_until_noise_start():
    cfg = ActorConfig(init_noise_std=1.0, final_noise_std=0.4, noise_start=0.25, noise_deadline=0.5)
    ceilings = [noise_ceiling(cfg, it, 20) for it in range(20)]
    assert ceilings[:6] == [1.0] * 6
    np.testing.assert_allclose(ceilings[5:11], 1.0 - 0.6 * np.arange(6) / 5)
    assert ceilings[10:] == pytest.approx([0.4] * 10)


def test_training_std_stays_under_the_ceiling(tmp_path, smoke_scene):
    cfg = smoke_cfg(
        "scale.max_iterations=4", "actor.final_noise_std=0.5", "actor.noise_deadline=0.5"
    )
    trainer = make_trainer(cfg, tmp_path / "run", smoke_scene)
    trainer.train()
    stds = [float(r["action_std"]) for r in read_curve(tmp_path / "run" / "train_curve.csv")]
    for it, std in enumerate(stds):
        assert std <= noise_ceiling(cfg.actor, it, 4) + 1e-6
    assert stds[-1] == pytest.approx(0.5, abs=1e-6)


def test_per_joint_initial_std(tmp_path, smoke_scene):
    cfg = smoke_cfg("scale.max_iterations=1")
    cfg.actor.init_noise_std_joints = {".*_knee_joint": 0.3}
    trainer = make_trainer(cfg, tmp_path / "run", smoke_scene)
    std = trainer.alg.get_policy().distribution.std_param.detach()
    names = trainer.env.scene.joint_names
    for i, name in enumerate(names):
        assert std[i] == pytest.approx(0.3 if "knee" in name else cfg.actor.init_noise_std)


def test_ceiling_can_follow_the_penalties():
    cfg = ActorConfig(
        init_noise_std=1.0, final_noise_std=0.4, noise_deadline=0.5, noise_by="penalties"
    )
    assert noise_ceiling(cfg, 0, 20, penalty_progress=0.0) == pytest.approx(1.0)
    assert noise_ceiling(cfg, 3, 20, penalty_progress=0.5) == pytest.approx(0.7)
    assert noise_ceiling(cfg, 10, 20, penalty_progress=0.0) == pytest.approx(0.4)  # deadline
