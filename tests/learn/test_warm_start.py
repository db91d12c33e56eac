"""`algo.init_from`: a new run starts from another run's networks, at iteration 0, with its
own optimizer and schedules."""

from __future__ import annotations

import pytest
import torch

from lca.learn.train_cfg import build_train_cfg

from .helpers import make_trainer, read_curve, smoke_cfg


@pytest.mark.slow  # trains: see README
def test_warm_start_loads_networks_not_iteration(tmp_path, smoke_scene) -> None:
    donor = make_trainer(smoke_cfg("scale.max_iterations=3"), tmp_path / "donor", smoke_scene)
    donor.train()
    source = tmp_path / "donor" / "checkpoints" / "latest.pt"
    saved = torch.load(source, weights_only=False)
    assert saved["iter"] == 2

    cfg = smoke_cfg("scale.max_iterations=2", f"algo.init_from={source}")
    warm = make_trainer(cfg, tmp_path / "warm", smoke_scene)
    assert warm.start == 0
    for key, value in saved["actor_state_dict"].items():
        torch.testing.assert_close(warm.alg.actor.state_dict()[key], value, msg=key)
    for key, value in saved["critic_state_dict"].items():
        torch.testing.assert_close(warm.alg.critic.state_dict()[key], value, msg=key)
    fresh = make_trainer(smoke_cfg("scale.max_iterations=2"), tmp_path / "fresh", smoke_scene)
    weight = "mlp.0.weight"
    assert not torch.equal(fresh.alg.actor.state_dict()[weight], saved["actor_state_dict"][weight])

    warm.train()
    assert [r["iteration"] for r in read_curve(tmp_path / "warm" / "train_curve.csv")] == ["0", "1"]


def test_warm_start_from_missing_file_names_the_key(tmp_path, smoke_scene) -> None:
    cfg = smoke_cfg(f"algo.init_from={tmp_path / 'nothing.pt'}")
    with pytest.raises(FileNotFoundError, match="algo.init_from"):
        make_trainer(cfg, tmp_path / "run", smoke_scene)


def test_init_from_is_not_passed_to_ppo() -> None:
    algorithm = build_train_cfg(smoke_cfg("algo.init_from=x.pt"), "run")["algorithm"]
    assert "init_from" not in algorithm


@pytest.mark.slow  # trains: see README
def test_critic_warmup_trains_the_critic_only(tmp_path, smoke_scene) -> None:
    cfg = smoke_cfg("scale.max_iterations=4", "algo.critic_warmup=2")
    trainer = make_trainer(cfg, tmp_path / "run", smoke_scene)
    actor0 = {k: v.clone() for k, v in trainer.alg.actor.state_dict().items()}
    critic0 = {k: v.clone() for k, v in trainer.alg.critic.state_dict().items()}
    trainer.train(hook=lambda trainer, it, row: it == 1)  # stopped after the warm-up
    weight = "mlp.0.weight"
    assert torch.equal(trainer.alg.actor.state_dict()[weight], actor0[weight])
    assert not torch.equal(trainer.alg.critic.state_dict()[weight], critic0[weight])
    rates = [float(r["learning_rate"]) for r in read_curve(tmp_path / "run" / "train_curve.csv")]
    assert rates == [cfg.algo.learning_rate] * 2  # held: no KL to adapt it to

    resumed = make_trainer(cfg, tmp_path / "run", smoke_scene)
    resumed.train()
    assert not torch.equal(resumed.alg.actor.state_dict()[weight], actor0[weight])
    assert all(p.requires_grad for p in resumed.alg.actor.parameters())


@pytest.mark.slow  # trains: see README
@pytest.mark.parametrize("encoder", ["mlp", "cnn"])
def test_a_blind_start_acts_the_same_and_its_map_has_no_say(tmp_path, smoke_scene, encoder):
    """Issue 28's common start: a blind MLP-encoder policy's networks start a perceptive one
    of either encoder; its actions and values equal the source's, whatever the map says."""
    donor_cfg = smoke_cfg("scale.max_iterations=2", "policy=blind")
    donor = make_trainer(donor_cfg, tmp_path / "donor", smoke_scene)
    donor.train()
    source = tmp_path / "donor" / "checkpoints" / "latest.pt"
    cfg = smoke_cfg(
        f"encoder={encoder}",
        "curriculum=one",
        f"algo.init_from={source}",
        "algo.init_map_zero=true",
    )
    warm = make_trainer(cfg, tmp_path / "warm", smoke_scene)
    obs = warm.env.get_observations()
    flat, bumpy = obs.clone(), obs.clone()
    flat["height"] = torch.zeros_like(obs["height"])
    flat["critic_height"] = torch.zeros_like(obs["critic_height"])
    bumpy["height"] = torch.rand_like(obs["height"])
    bumpy["critic_height"] = torch.rand_like(obs["critic_height"])
    with torch.no_grad():
        expected = donor.alg.actor(flat, stochastic_output=False)
        value = donor.alg.critic(flat)
        for sees in (flat, bumpy):
            torch.testing.assert_close(warm.alg.actor(sees, stochastic_output=False), expected)
            torch.testing.assert_close(warm.alg.critic(sees), value)
    first = warm.alg.actor.state_dict()["mlp.0.weight"]
    assert torch.all(first[:, -warm.alg.actor._z_dim :] == 0)


def test_map_zero_start_needs_a_blind_mlp_encoder_source(tmp_path) -> None:
    from lca.learn.warm_start import encoder_at_zero

    conv = {"encoder.net.0.weight": torch.zeros(4, 1, 3, 3), "encoder.net.0.bias": torch.zeros(4)}
    with pytest.raises(ValueError, match="not an MLP"):
        encoder_at_zero(conv, "elu")
    with pytest.raises(ValueError, match="no encoder"):
        encoder_at_zero({"mlp.0.weight": torch.zeros(2, 2)}, "elu")


def test_map_zero_start_refuses_a_recurrent_actor() -> None:
    from types import SimpleNamespace

    from lca.learn.warm_start import zero_map_state

    with pytest.raises(ValueError, match="recurrent actor"):
        zero_map_state({}, SimpleNamespace(is_recurrent=True), "elu")


def test_widen_history_inserts_silent_older_frames() -> None:
    from types import SimpleNamespace

    from lca.learn.warm_start import widen_history

    frame, current, hidden = 3, 2, 4
    stats = torch.arange(2 * frame + current, dtype=torch.float32)[None]  # 2 frames, then current
    weight = torch.randn(hidden, 2 * frame + current + 5)  # 5: an encoder's features
    source = {
        "obs_normalizer._mean": stats,
        "obs_normalizer._var": stats + 100,
        "obs_normalizer._std": stats + 200,
        "obs_normalizer.count": torch.tensor(7),
        "mlp.0.weight": weight,
        "mlp.0.bias": torch.ones(hidden),
    }

    def target(obs_dim: int, **kw) -> SimpleNamespace:
        normaliser = SimpleNamespace(_mean=torch.zeros(1, obs_dim))
        return SimpleNamespace(obs_normalizer=normaliser, **kw)

    state = widen_history(source, target(4 * frame + current), frame_dim=frame, frames=4)
    mean = state["obs_normalizer._mean"][0].tolist()
    assert mean == [0, 1, 2, 3, 4, 5, 0, 1, 2, 0, 1, 2, 6, 7]  # the newest frame's statistics
    assert state["obs_normalizer._std"][0, 6:9].tolist() == [200, 201, 202]
    widened = state["mlp.0.weight"]
    assert widened.shape == (hidden, 4 * frame + current + 5)
    torch.testing.assert_close(widened[:, : 2 * frame], weight[:, : 2 * frame])
    assert torch.all(widened[:, 2 * frame : 4 * frame] == 0)
    torch.testing.assert_close(widened[:, 4 * frame :], weight[:, 2 * frame :])
    assert state["obs_normalizer.count"] == 7 and state["mlp.0.bias"] is source["mlp.0.bias"]
    with pytest.raises(ValueError, match="task.observations.history=4"):
        widen_history(source, target(4 * frame + current + 1), frame_dim=frame, frames=4)
    with pytest.raises(ValueError, match="obs_normalization"):
        widen_history(source, SimpleNamespace(obs_normalizer=None), frame_dim=frame, frames=4)
    with pytest.raises(ValueError, match="recurrent"):
        widen_history(source, target(14, is_recurrent=True), frame_dim=frame, frames=4)


@pytest.mark.slow  # trains: see README
def test_a_shorter_history_starts_a_longer_one_acting_the_same(tmp_path, smoke_scene) -> None:
    donor = make_trainer(
        smoke_cfg("scale.max_iterations=2", "policy=blind", "task.observations.history=2"),
        tmp_path / "donor",
        smoke_scene,
    )
    donor.train()
    source = tmp_path / "donor" / "checkpoints" / "latest.pt"
    cfg = smoke_cfg(
        "policy=blind",
        "task.observations.history=4",
        f"algo.init_from={source}",
        "algo.init_widen_history=true",
    )
    warm = make_trainer(cfg, tmp_path / "warm", smoke_scene)
    frame = warm.env.history.buffer.shape[2]
    obs = warm.env.get_observations()
    seen = obs.clone()
    seen["policy"] = torch.randn_like(obs["policy"])
    seen["critic"] = torch.randn_like(obs["critic"])
    short = seen.clone(recurse=False)
    for group in ("policy", "critic"):  # the donor's view: its two newest frames, then the rest
        short[group] = torch.cat([seen[group][:, : 2 * frame], seen[group][:, 4 * frame :]], 1)
    with torch.no_grad():
        torch.testing.assert_close(
            warm.alg.actor(seen, stochastic_output=False),
            donor.alg.actor(short, stochastic_output=False),
        )
        torch.testing.assert_close(warm.alg.critic(seen), donor.alg.critic(short))
    warm.train()  # the widened networks train


def test_a_different_history_without_widening_fails_to_load(tmp_path, smoke_scene) -> None:
    donor = make_trainer(
        smoke_cfg("scale.max_iterations=1", "task.observations.history=2"),
        tmp_path / "donor",
        smoke_scene,
    )
    donor.save("latest.pt", 0)
    source = tmp_path / "donor" / "checkpoints" / "latest.pt"
    cfg = smoke_cfg("task.observations.history=3", f"algo.init_from={source}")
    with pytest.raises(RuntimeError, match="size mismatch"):
        make_trainer(cfg, tmp_path / "warm", smoke_scene)
