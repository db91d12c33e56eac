"""Deployable exports of a trained actor: one self-contained ONNX file with a dynamic batch,
and TorchScript.

ONNX inputs: `obs` (batch, D) and the heightmap (batch, 1, H, W); an LSTM actor also takes
and returns its state, `h_in`/`c_in` -> `h_out`/`c_out` of shape (layers, batch, hidden).
The weights live inside the .onnx file (TorchScript-based exporter), so the file can be
copied alone.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import torch
from torch import nn

from lca.store import write_atomically

ONNX_OPSET = 17


def _dynamic_axes(module: nn.Module) -> dict[str, dict[int, str]]:
    axes = {name: {0: "batch"} for name in module.input_names[:2] + module.output_names[:1]}
    if module.is_recurrent:
        axes |= {name: {1: "batch"} for name in ("h_in", "c_in", "h_out", "c_out")}
    return axes


def _write_atomically(path: Path, write) -> Path:
    """`write(tmp)`, then renamed to `path` (lca.store), without the exporters' notices."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the exporters' deprecation notices
        return write_atomically(path, write)


def export_onnx(actor, path: Path) -> Path:
    """Write the actor's deterministic policy to `path` atomically."""
    module = actor.as_onnx().to("cpu").eval()
    return _write_atomically(
        path,
        lambda tmp: torch.onnx.export(
            module,
            module.get_dummy_inputs(),
            tmp,
            input_names=module.input_names,
            output_names=module.output_names,
            dynamic_axes=_dynamic_axes(module),
            opset_version=ONNX_OPSET,
            dynamo=False,
        ),
    )


def export_jit(actor, path: Path) -> Path:
    """TorchScript of the actor (an LSTM keeps its state inside; `reset()` clears it)."""
    module = actor.as_jit().to("cpu").eval()
    return _write_atomically(path, lambda tmp: torch.jit.save(torch.jit.script(module), tmp))
