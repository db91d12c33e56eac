"""`device=auto` picks the GPU when torch sees one and the CPU otherwise."""

from __future__ import annotations

import torch

from lca.config import compose, resolve_device


def test_auto_follows_cuda_availability(monkeypatch) -> None:
    monkeypatch.setattr(torch.cuda, "is_available", lambda: True)
    assert resolve_device("auto") == "cuda"
    monkeypatch.setattr(torch.cuda, "is_available", lambda: False)
    assert resolve_device("auto") == "cpu"
    assert resolve_device("cuda:1") == "cuda:1"  # anything else is taken as given
    assert resolve_device("cpu") == "cpu"


def test_auto_is_the_default_device() -> None:
    assert compose(["scale=smoke"]).device == "auto"
