"""The walking policy shipped in assets/policies/blind_flat: a complete, small run directory
whose checkpoint loads and steps, and whose exports act like it."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import torch
from omegaconf import OmegaConf

from lca.evaluate.config import EvalCell
from lca.evaluate.policy import final_checkpoint, load_policy, load_run_config
from lca.evaluate.protocol import cell_config
from lca.task.env import LocomotionEnv

SHIPPED = Path(__file__).resolve().parents[2] / "assets" / "policies" / "blind_flat"
FILES = (
    "config.yaml",
    "provenance.json",
    "train_cfg.json",
    "train_curve.csv",
    "exported/policy.onnx",
    "exported/policy.pt",
    "summary.csv",
)


def test_shipped_run_is_complete_and_small():
    for name in FILES:
        assert (SHIPPED / name).is_file(), name
    checkpoint = final_checkpoint(SHIPPED)
    state = torch.load(checkpoint, map_location="cpu", weights_only=False)
    assert "optimizer_state_dict" not in state
    assert "actor_state_dict" in state
    sizes = {p.name: p.stat().st_size for p in SHIPPED.rglob("*") if p.is_file()}
    assert max(sizes.values()) < 4.5e6, sizes  # nothing over a few MB
    assert sum(sizes.values()) < 10e6, f"{sum(sizes.values()) / 1e6:.1f} MB"


@pytest.fixture(scope="module")
def rollout():
    cfg = load_run_config(SHIPPED, ["eval.units=4", "eval.steps=100", "sim.num_threads=1"])
    env = LocomotionEnv(cell_config(cfg, OmegaConf.structured(EvalCell("flat", "medium"))))
    env.set_perception(False)
    policy = load_policy(cfg, env, final_checkpoint(SHIPPED))
    env.reseed(0)
    obs = env.reset_all()
    samples, alive = [], np.ones(env.num_envs, dtype=bool)
    with torch.inference_mode():
        for _ in range(100):
            actions = policy(obs)
            samples.append((obs["policy"][:1].clone(), obs["height"][:1].clone(), actions[:1]))
            obs, _, _, extras = env.step(actions)
            alive &= ~extras["metrics"]["terminated"]
    return samples, alive


def test_shipped_policy_loads_and_steps(rollout):
    samples, alive = rollout
    assert all(torch.isfinite(a).all() for _, _, a in samples)
    assert alive.all()  # two seconds of walking without a fall


def test_exports_act_like_the_checkpoint(rollout):
    ort = pytest.importorskip("onnxruntime")
    onnx = ort.InferenceSession(str(SHIPPED / "exported" / "policy.onnx"))
    jit = torch.jit.load(str(SHIPPED / "exported" / "policy.pt"))
    batch = torch.cat([s[0] for s in rollout[0][:8]]), torch.cat([s[1] for s in rollout[0][:8]])
    expected = torch.cat([s[2] for s in rollout[0][:8]]).numpy()
    for i in range(8):
        (actions,) = onnx.run(
            ["actions"], {"obs": batch[0][i : i + 1].numpy(), "height": batch[1][i : i + 1].numpy()}
        )
        np.testing.assert_allclose(actions[0], expected[i], atol=1e-4)
        with torch.no_grad():
            np.testing.assert_allclose(
                jit(batch[0][i : i + 1], batch[1][i : i + 1])[0].numpy(), expected[i], atol=1e-4
            )
