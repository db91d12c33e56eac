"""Find run directories and read what the earlier stages wrote into them."""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import pandas as pd
from omegaconf import OmegaConf

from lca.config.registry import ACTORS, ENCODERS

ROW_ORDER = [
    "Blind",
    "One-Stage MLP",
    "Two-Stage MLP",
    "One-Stage LSTM",
    "Two-Stage LSTM",
    "One-Stage CNN",
    "Two-Stage CNN",
]
STAGES = {"one": "One-Stage", "two": "Two-Stage"}


POOLED = " (pooled)"  # a CNN with max-pooling is not the paper's CNN


def policy_label(curriculum: str, actor: str, encoder: str, pool: int = 0) -> str:
    """The paper's row name, from the run's composed config (never from folder names) and the
    registered labels of its actor and encoder kinds (lca.learn.variants).

    MLP = MLP actor + MLP encoder, CNN = MLP actor + CNN encoder, LSTM = LSTM actor
    (+ MLP encoder; with a CNN encoder it is reported as LSTM-CNN), and likewise for any
    registered actor kind. A CNN encoder with max-pooling (`encoder.pool`) reads
    "CNN (pooled)". A kind nobody registered fails loudly, naming the allowed ones."""
    if curriculum == "blind":
        return "Blind"
    actor_label = ACTORS.label(actor)
    encoder_label = ENCODERS.label(encoder)
    if actor == "mlp":
        arch = encoder_label
    else:
        arch = actor_label if encoder == "mlp" else f"{actor_label}-{encoder_label}"
    pooled = POOLED if encoder == "cnn" and pool > 1 else ""
    return f"{STAGES.get(curriculum, curriculum)} {arch}{pooled}"


def row_key(label: str) -> tuple[int, str]:
    base = label.removesuffix(POOLED)
    return (ROW_ORDER.index(base) if base in ROW_ORDER else len(ROW_ORDER), label)


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
        label=policy_label(
            cfg.curriculum.name, cfg.actor.kind, cfg.encoder.kind, int(cfg.encoder.get("pool", 0))
        ),
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
