"""The run directory: provenance, completion marker, curves and checkpoint paths.

Stages talk through these files, so any stage can be re-run alone.
"""

from __future__ import annotations

import json
import os
import platform
import socket
import subprocess
import sys
import tempfile
import time
from importlib import metadata
from pathlib import Path

from omegaconf import DictConfig, OmegaConf

PACKAGES = ("lca", "torch", "mujoco", "mjbatch", "rsl-rl-lib", "hydra-core", "numpy", "tensordict")
COMPLETE = "COMPLETE"


def atomic_write(path: Path, text: str) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.")
    with os.fdopen(fd, "w") as f:
        f.write(text)
    os.replace(tmp, path)


def git_state(repo: Path) -> dict:
    def git(*args: str) -> str:
        out = subprocess.run(["git", *args], cwd=repo, capture_output=True, text=True, check=False)
        return out.stdout.strip()

    commit = git("rev-parse", "HEAD")
    return {
        "commit": commit or None,
        "dirty": bool(git("status", "--porcelain")) if commit else None,
    }


def versions() -> dict:
    found = {}
    for name in PACKAGES:
        try:
            found[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            found[name] = None
    return found


class RunDir:
    def __init__(self, path: str | Path):
        self.path = Path(path)
        self.checkpoints = self.path / "checkpoints"
        self.exported = self.path / "exported"
        self.curve = self.path / "train_curve.csv"

    @property
    def complete(self) -> bool:
        return (self.path / COMPLETE).exists()

    def mark_complete(self, summary: dict) -> None:
        atomic_write(self.path / COMPLETE, json.dumps(summary, indent=2))

    def clear_complete(self) -> None:
        (self.path / COMPLETE).unlink(missing_ok=True)

    def write_provenance(self, cfg: DictConfig, overrides: list[str], choices: dict) -> None:
        repo = Path(__file__).resolve().parents[3]
        atomic_write(self.path / "config.yaml", OmegaConf.to_yaml(cfg, resolve=True))
        provenance = {
            "overrides": list(overrides),
            "choices": dict(choices),
            "seed": int(cfg.seed),
            "git": git_state(repo),
            "versions": versions(),
            "python": sys.version.split()[0],
            "platform": platform.platform(),
            "host": socket.gethostname(),
            "argv": sys.argv,
            "started": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
        }
        atomic_write(self.path / "provenance.json", json.dumps(provenance, indent=2))

    def latest_checkpoint(self) -> Path | None:
        path = self.checkpoints / "latest.pt"
        return path if path.exists() else None
