"""Actor/critic models: heightmap encoders, LSTM state at episode ends, and the exported
policies (ONNX, TorchScript) against the torch policy."""

from __future__ import annotations

import copy
import shutil

import numpy as np
import pytest
import torch
from tensordict import TensorDict

from lca.learn.encoders import HeightmapEncoder
from lca.learn.train_cfg import encoder_cfg

from .helpers import make_trainer, smoke_cfg


@pytest.mark.parametrize("kind", ["cnn", "mlp"])
def test_encoder_folds_leading_dims(kind: str) -> None:
    """(T, B, C, H, W) maps encode like T*B separate (C, H, W) maps: the same module serves
    rollouts and recurrent mini-batches."""
    torch.manual_seed(0)
    enc = HeightmapEncoder(shape=(1, 11, 11), **encoder_cfg(smoke_cfg(f"encoder={kind}")))
    maps = torch.randn(3, 5, 1, 11, 11)
    z = enc(maps)
    assert z.shape == (3, 5, enc.latent_dim)
    flat = enc(maps.reshape(15, 1, 11, 11)).reshape(3, 5, -1)
    torch.testing.assert_close(z, flat)
    assert not torch.allclose(z[0, 0], z[0, 1])  # the map reaches the latent
    has_conv = any(isinstance(m, torch.nn.Conv2d) for m in enc.modules())
    assert has_conv == (kind == "cnn")


def test_encoder_rejects_unknown_kind() -> None:
    with pytest.raises(ValueError, match="encoder.kind"):
        HeightmapEncoder("gru", (1, 11, 11), [8], 4, [])


# ---- LSTM hidden state ---------------------------------------------------------------------


def test_lstm_state_reset_where_episodes_end(smoke_scene, tmp_path) -> None:
    """Drive PPO's act/process_env_step loop on the real env; on the 3rd step envs 1 and 4 end
    their episodes. Their LSTM rows (h and c) are zeroed, the others are kept, and the next
    action of a reset env equals that of a freshly started policy."""
    trainer = make_trainer(smoke_cfg("actor=lstm"), tmp_path / "run", smoke_scene)
    alg, env = trainer.alg, trainer.env
    actor = alg.get_policy()
    assert actor.is_recurrent and not alg.critic.is_recurrent
    alg.train_mode()
    obs = env.get_observations()
    ended = torch.zeros(env.num_envs, dtype=torch.bool)
    ended[[1, 4]] = True
    with torch.inference_mode():
        for step in range(3):
            actions = alg.act(obs)
            obs, rewards, dones, extras = env.step(actions)
            if step == 2:
                assert not dones[~ended].any(), "an env really ended; pick other rows"
                dones = dones.clone()
                dones[ended] = 1
                before = tuple(s.clone() for s in actor.get_hidden_state())
            alg.process_env_step(obs, rewards, dones, extras)
        h, c = actor.get_hidden_state()
        assert h.shape == c.shape == (1, env.num_envs, actor.rnn.rnn.hidden_size)
        for state, old in zip((h, c), before, strict=True):
            assert torch.all(state[:, ended] == 0)
            assert torch.all(state[:, ~ended].abs().amax(dim=-1) > 0)
            assert torch.equal(state[:, ~ended], old[:, ~ended])
            assert torch.all(old[:, ended].abs().amax(dim=-1) > 0)  # they were not zero before

        fresh = copy.deepcopy(actor)
        fresh.reset()
        assert fresh.get_hidden_state() is None
        carried = copy.deepcopy(actor)
        a_fresh, a_carried = fresh(obs), carried(obs)
    torch.testing.assert_close(a_carried[ended], a_fresh[ended], atol=1e-6, rtol=0)
    assert (a_carried[~ended] - a_fresh[~ended]).abs().amax(dim=-1).min() > 1e-6


# ---- exports -------------------------------------------------------------------------------


@pytest.fixture(scope="module", params=["mlp", "lstm"])
def exported(request, smoke_scene, tmp_path_factory) -> dict:
    """A 2-iteration run (encoder cnn, curriculum two) with its exports, and 3 observations
    (batch 1) with perception on, as a short sequence."""
    actor = request.param
    cfg = smoke_cfg(f"actor={actor}", "encoder=cnn")
    trainer = make_trainer(cfg, tmp_path_factory.mktemp(f"export_{actor}"), smoke_scene)
    trainer.train()
    paths = trainer.export()
    obs = trainer.env.get_observations()
    assert obs["height"][:3].abs().amax() > 0
    return {
        "actor": actor,
        "paths": paths,
        "policy": trainer.alg.get_policy(),
        "num_actions": trainer.env.num_actions,
        "samples": [(obs["policy"][i : i + 1], obs["height"][i : i + 1]) for i in range(3)],
        "batch": obs,
    }


def _torch_actions(policy, samples) -> list[np.ndarray]:
    policy.eval()
    policy.reset()
    out = []
    with torch.no_grad():
        for flat, height in samples:
            td = TensorDict({"policy": flat, "height": height}, batch_size=[1])
            out.append(policy(td).numpy())
    return out


def _onnx_actions(path, recurrent: bool, samples) -> tuple[list[str], list[np.ndarray]]:
    ort = pytest.importorskip("onnxruntime")
    sess = ort.InferenceSession(str(path), providers=["CPUExecutionProvider"])
    names = [i.name for i in sess.get_inputs()]
    out, state = [], None
    for flat, height in samples:
        feed = {"obs": flat.numpy(), "height": height.numpy()}
        if recurrent:
            if state is None:
                shapes = {i.name: i.shape for i in sess.get_inputs()}
                state = [  # the batch axis is symbolic: one sequence here
                    np.zeros([d if isinstance(d, int) else 1 for d in shapes[k]], np.float32)
                    for k in ("h_in", "c_in")
                ]
            feed |= {"h_in": state[0], "c_in": state[1]}
            actions, h, c = sess.run(["actions", "h_out", "c_out"], feed)
            state = [h, c]
        else:
            (actions,) = sess.run(["actions"], feed)
        out.append(actions)
    return names, out


def _jit_actions(path, samples) -> list[np.ndarray]:
    jit = torch.jit.load(str(path))
    jit.reset()
    with torch.no_grad():
        return [jit(flat, height).numpy() for flat, height in samples]


def test_exported_policies_match_torch(exported) -> None:
    recurrent = exported["actor"] == "lstm"
    samples = exported["samples"]
    reference = _torch_actions(exported["policy"], samples)
    names, onnx = _onnx_actions(exported["paths"]["onnx"], recurrent, samples)
    assert names == (["obs", "height", "h_in", "c_in"] if recurrent else ["obs", "height"])
    jit = _jit_actions(exported["paths"]["torchscript"], samples)
    for step, ref in enumerate(reference):
        assert ref.shape == (1, exported["num_actions"])
        np.testing.assert_allclose(onnx[step], ref, atol=1e-4, rtol=0, err_msg=f"onnx {step}")
        np.testing.assert_allclose(jit[step], ref, atol=1e-4, rtol=0, err_msg=f"jit {step}")
    # different observations give different actions (the comparison is not vacuous)
    assert np.abs(reference[0] - reference[1]).max() > 1e-4


@pytest.mark.parametrize("exported", ["lstm"], indirect=True)
def test_exported_lstm_carries_state(exported) -> None:
    """A recurrent export must depend on its state: the 2nd action differs from the action a
    reset policy gives for the same observation."""
    samples = exported["samples"]
    seq = _onnx_actions(exported["paths"]["onnx"], True, samples[:2])[1]
    alone = _onnx_actions(exported["paths"]["onnx"], True, samples[1:2])[1]
    assert np.abs(seq[1] - alone[0]).max() > 1e-6
    jit_seq = _jit_actions(exported["paths"]["torchscript"], samples[:2])
    jit_alone = _jit_actions(exported["paths"]["torchscript"], samples[1:2])
    np.testing.assert_allclose(jit_alone[0], alone[0], atol=1e-4, rtol=0)
    np.testing.assert_allclose(jit_seq[1], seq[1], atol=1e-4, rtol=0)


@pytest.mark.parametrize("batch", [1, 64])
def test_onnx_is_one_file_with_a_dynamic_batch(exported, batch, tmp_path) -> None:
    """policy.onnx copied alone loads, and takes a batch of any size."""
    ort = pytest.importorskip("onnxruntime")
    alone = tmp_path / "policy.onnx"
    shutil.copyfile(exported["paths"]["onnx"], alone)
    assert [p.name for p in tmp_path.iterdir()] == ["policy.onnx"]
    sess = ort.InferenceSession(str(alone), providers=["CPUExecutionProvider"])
    obs = exported["batch"]
    index = torch.arange(batch) % obs.batch_size[0]
    flat, height = obs["policy"][index], obs["height"][index]
    flat = flat + 0.01 * torch.arange(batch)[:, None]  # distinct rows
    feed = {"obs": flat.numpy(), "height": height.numpy()}
    policy = exported["policy"]
    policy.eval()
    policy.reset()
    with torch.no_grad():
        expected = policy(TensorDict({"policy": flat, "height": height}, batch_size=[batch]))
    if exported["actor"] == "lstm":
        shapes = {i.name: i.shape for i in sess.get_inputs()}
        layers, hidden = shapes["h_in"][0], shapes["h_in"][2]
        zeros = np.zeros((layers, batch, hidden), dtype=np.float32)
        feed |= {"h_in": zeros, "c_in": zeros}
    actions = sess.run(["actions"], feed)[0]
    assert actions.shape == (batch, exported["num_actions"])
    np.testing.assert_allclose(actions, expected.numpy(), atol=1e-4, rtol=0)
