"""Load a run's config and final policy from its run directory."""

from __future__ import annotations

import contextlib
import copy
import io
from pathlib import Path

from omegaconf import DictConfig, OmegaConf
from rsl_rl.runners import OnPolicyRunner

from lca.config import override_config, schema, validate
from lca.config.runtime import resolve_device
from lca.store import RunDir
from lca.task.env import LocomotionEnv

STAGES = ("blind", "perception")  # the names of the trainer's final checkpoints


def load_run_config(run_dir: Path, overrides: list[str] | None = None) -> DictConfig:
    """The run's resolved config.yaml, checked against the schema, with `overrides` applied
    as `run.py` applies them (dotted keys and group options such as `scale=smoke`)."""
    path = Path(run_dir) / "config.yaml"
    if not path.exists():
        raise FileNotFoundError(f"run_dir: {run_dir} has no config.yaml (not a run directory)")
    cfg = OmegaConf.merge(OmegaConf.structured(schema.LcaConfig), OmegaConf.load(path))
    validate(cfg)
    if overrides:
        own = RunDir(run_dir).provenance().get("overrides", [])
        cfg = override_config(cfg, list(overrides), own)
    return cfg


def final_checkpoint(run_dir: Path) -> Path:
    """`checkpoints/final_<stage>.pt`: the trainer names the final policy by its curriculum
    stage (`blind` or `perception`), which decides whether it sees its map."""
    finals = sorted((Path(run_dir) / "checkpoints").glob("final_*.pt"))
    if not finals:
        raise FileNotFoundError(f"run_dir: {run_dir} has no checkpoints/final_*.pt; train it first")
    return finals[-1]


def sees_map(checkpoint: Path) -> bool:
    """Whether the policy of a final checkpoint acts on its heightmap (its training stage)."""
    stage = Path(checkpoint).stem.removeprefix("final_")
    if stage not in STAGES:
        raise ValueError(f"checkpoint: {checkpoint} is not final_<stage>.pt, stage in {STAGES}")
    return stage == "perception"


def _runner(cfg: DictConfig, env: LocomotionEnv, train_cfg: dict) -> OnPolicyRunner:
    with contextlib.redirect_stdout(io.StringIO()):  # rsl-rl prints the model summaries
        return OnPolicyRunner(
            env, copy.deepcopy(train_cfg), log_dir=None, device=resolve_device(cfg.device)
        )


def new_policy(cfg: DictConfig, env: LocomotionEnv, train_cfg: dict):
    """A freshly initialised actor for `env` from an rsl-rl runner config, in evaluation
    mode (load weights into it)."""
    return _runner(cfg, env, train_cfg).get_inference_policy(resolve_device(cfg.device))


def load_policy(cfg: DictConfig, env: LocomotionEnv, checkpoint: Path):
    """The deterministic actor of `checkpoint` (in `<run>/checkpoints/`), built from the
    run's `train_cfg.json`: `policy(obs)`, `policy.reset(dones)`."""
    device = resolve_device(cfg.device)
    runner = _runner(cfg, env, RunDir(Path(checkpoint).parent.parent).train_cfg())
    try:
        runner.load(str(checkpoint), load_cfg={"actor": True}, strict=True, map_location=device)
    except (RuntimeError, EOFError, OSError, KeyError) as error:
        reason = str(error).splitlines()[0][:200] if str(error) else type(error).__name__
        raise RuntimeError(
            f"cannot read checkpoint {checkpoint}: {reason}. Retrain the run (force=true) or "
            f"replace the file with a readable checkpoint of the same configuration"
        ) from error
    return runner.get_inference_policy(device)
