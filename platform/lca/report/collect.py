"""Find run directories and read what the earlier stages wrote into them."""

from __future__ import annotations

import json
from dataclasses import dataclass
from functools import cache
from pathlib import Path

import pandas as pd
from omegaconf import DictConfig, OmegaConf

from lca.config.policies import known_policies, matching_policy, unlabelled_error

POOLED = " (pooled)"  # a CNN with max-pooling is not the paper's CNN
# label -> row of every policy block seen (conf/policy/*.yaml and the runs loaded so far)
_ROWS: dict[str, int] = {}


def policy_label(cfg: DictConfig, where: str = "run") -> tuple[str, int]:
    """(row name, row number) of a run: the `policy` block that composition put into its
    config.yaml from conf/policy/*.yaml (never from folder names). A config older than those
    blocks is matched against the project's policy files now. A run that matches none fails
    loudly, naming its choices and the known policies: nothing is pooled into another row.
    A CNN encoder with max-pooling (`encoder.pool`) reads "<label> (pooled)"."""
    policy = cfg.get("policy")
    if not (policy and policy.get("label")):
        policy = matching_policy(cfg)
    if policy is None:
        raise ValueError(unlabelled_error(where, cfg))
    _ROWS[policy.label] = int(policy.row)
    pooled = POOLED if cfg.encoder.kind == "cnn" and int(cfg.encoder.get("pool", 0)) > 1 else ""
    return policy.label + pooled, int(policy.row)


@cache
def _project_rows() -> dict[str, int]:
    return {p.label: p.row for p in known_policies().values()}


def row_key(label: str) -> tuple[int, str]:
    base = label.removesuffix(POOLED)
    return (_ROWS.get(base, _project_rows().get(base, 1000)), label)


@dataclass
class RunRecord:
    path: Path
    label: str
    curriculum: str
    actor: str
    encoder: str
    seed: int
    provenance: dict
    episodes: pd.DataFrame | None
    curve: pd.DataFrame | None
    hardware: pd.DataFrame | None = None
    scale: str = "cpu"

    @property
    def name(self) -> str:
        return self.path.name


def is_run_dir(path: Path) -> bool:
    return (path / "config.yaml").exists() and (path / "provenance.json").exists()


def find_run_dirs(paths: list[Path]) -> list[Path]:
    """Run directories among `paths` and, for sweep folders, their direct subfolders."""
    found = []
    for path in map(Path, paths):
        if is_run_dir(path):
            found.append(path)
        elif path.is_dir():
            found += sorted(p for p in path.iterdir() if p.is_dir() and is_run_dir(p))
    return found


def run_status(path: Path) -> tuple[str, str]:
    """("complete" | "failed" | "incomplete", reason) of a run directory."""
    if (path / "COMPLETE").exists():
        return "complete", ""
    failed = path / "FAILED"
    if failed.exists():
        reason = json.loads(failed.read_text())
        return "failed", f"{reason.get('error')}: {reason.get('message', '')}"
    return "incomplete", "no COMPLETE marker (still running, interrupted or never finished)"


def load_run(path: Path) -> RunRecord:
    cfg = OmegaConf.load(path / "config.yaml")
    provenance = json.loads((path / "provenance.json").read_text())
    results = path / "results.parquet"
    curve = path / "train_curve.csv"
    hardware = path / "hardware.csv"
    return RunRecord(
        path=path,
        label=policy_label(cfg, str(path))[0],
        curriculum=cfg.curriculum.name,
        actor=cfg.actor.kind,
        encoder=cfg.encoder.kind,
        seed=int(cfg.seed),
        provenance=provenance,
        episodes=pd.read_parquet(results) if results.exists() else None,
        curve=pd.read_csv(curve) if curve.exists() else None,
        hardware=pd.read_csv(hardware) if hardware.exists() else None,
        scale=str(cfg.scale.name),
    )
