"""Runtime knobs read from the config: torch device, threads, run-directory naming."""

from __future__ import annotations

import torch
from omegaconf import OmegaConf


def resolve_device(device: str) -> str:
    """`auto` -> `cuda` when a GPU is visible, else `cpu`; anything else is used as given."""
    if device == "auto":
        return "cuda" if torch.cuda.is_available() else "cpu"
    return device


def set_torch_threads(threads: int) -> None:
    if threads > 0:
        torch.set_num_threads(threads)


def run_name(override_dirname: str) -> str:
    """Directory name of a run: its sorted overrides, or `default` when there are none."""
    return override_dirname or "default"


def gpus_for(device: str) -> int:
    """GPUs a cluster job asks for: one when the run's torch device is `cuda`, else none."""
    return 1 if str(device).startswith("cuda") else 0


def register_resolvers() -> None:
    if not OmegaConf.has_resolver("lca_run_name"):
        OmegaConf.register_new_resolver("lca_run_name", run_name)
    if not OmegaConf.has_resolver("lca_gpus"):
        OmegaConf.register_new_resolver("lca_gpus", gpus_for)
