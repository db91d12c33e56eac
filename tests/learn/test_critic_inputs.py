"""The asymmetric critic reads the privileged groups (noise-free proprioception with the
world-frame base velocity, and the 16 x 16 map), never the actor's noisy ones: checked by a
hook on what each model reads during a real PPO iteration."""

from __future__ import annotations

import torch

from lca.learn.models import PerceptiveMLPModel

from .helpers import make_trainer, smoke_cfg


def test_the_critic_reads_the_privileged_groups(smoke_scene, tmp_path, monkeypatch) -> None:
    seen: dict[str, list] = {}
    features = PerceptiveMLPModel._features

    def recording(self, obs):
        width = sum(obs[g].shape[-1] for g in self.obs_groups)
        seen.setdefault(self.image_group, []).append((tuple(self.obs_groups), width))
        return features(self, obs)

    monkeypatch.setattr(PerceptiveMLPModel, "_features", recording)
    cfg = smoke_cfg("curriculum=one", "scale.max_iterations=1")
    trainer = make_trainer(cfg, tmp_path / "run", smoke_scene)
    trainer.train()
    assert set(seen) == {"height", "critic_height"}  # the actor's map and the critic's
    for groups, _ in seen["critic_height"]:
        assert groups == ("critic",)
    for groups, _ in seen["height"]:
        assert groups == ("policy",)
    env = trainer.env
    obs = env.get_observations()
    # the critic's inputs are wider (world-frame velocity) and noise-free: not the policy's
    assert obs["critic"].shape[1] == obs["policy"].shape[1] + 3
    assert obs["critic_height"].shape[-2:] == (16, 16)
    assert obs["height"].shape[-2:] == (11, 11)
    assert {width for _, width in seen["critic_height"]} == {obs["critic"].shape[1]}
    assert not torch.equal(obs["critic"][:, : obs["policy"].shape[1]], obs["policy"])
