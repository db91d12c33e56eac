"""Evaluation loads a policy from its run directory's files alone: the networks from
train_cfg.json, whether it sees its map from the final checkpoint's stage."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from omegaconf import OmegaConf

from lca.evaluate.config import EvalCell
from lca.evaluate.policy import final_checkpoint, load_policy, load_run_config, sees_map
from lca.evaluate.protocol import cell_config
from lca.task.env import LocomotionEnv

SHIPPED = Path(__file__).resolve().parents[2] / "assets" / "policies" / "blind_flat"


@pytest.mark.parametrize(
    ("name", "sees"), [("final_blind.pt", False), ("final_perception.pt", True)]
)
def test_the_final_stage_decides_the_map(name: str, sees: bool) -> None:
    assert sees_map(Path("run/checkpoints") / name) is sees


def test_an_unknown_stage_is_refused() -> None:
    with pytest.raises(ValueError, match=r"final_warmup\.pt is not final_<stage>\.pt"):
        sees_map(Path("final_warmup.pt"))


def test_a_run_without_train_cfg_names_the_missing_file(tmp_path) -> None:
    run = tmp_path / "run"
    shutil.copytree(SHIPPED, run)
    cfg = load_run_config(run, ["eval.units=2", "sim.num_threads=1"])
    env = LocomotionEnv(cell_config(cfg, OmegaConf.structured(EvalCell("flat", "medium"))))
    policy = load_policy(cfg, env, final_checkpoint(run))  # loads from the copy's files
    assert policy(env.reset_all()).shape == (2, env.num_actions)
    (run / "train_cfg.json").unlink()
    with pytest.raises(FileNotFoundError, match=r"has no train_cfg\.json .*train it"):
        load_policy(cfg, env, final_checkpoint(run))
