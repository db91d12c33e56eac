"""Warm starts that change the network's inputs but not, at first, its outputs.

`algo.init_map_zero`: a map that contributes nothing at first.

Issue 28's common start: every policy of the reference set, whatever its encoder, starts from
the networks of one blind walker. A blind policy's encoder only ever saw the zero map, so it
is one constant vector z0 to the first layer after it. The transplant folds W_z z0 into that
layer's bias and zeroes W_z: the new network computes exactly the source's actions and values
(on a zero map) while its own encoder, freshly initialised, starts with no say. The columns W_z
get gradients from the first update, and through them the encoder.

`algo.init_widen_history`: a source trained with a shorter proprioception history starts a run
with a longer one. The frames it never saw get zero weights (the same actions and values at
first) and its normaliser's statistics of the newest frame, so the gradient can give them a say.
"""

from __future__ import annotations

import re

import torch
from rsl_rl.utils import resolve_nn_activation
from torch import nn

FIRST_LAYER = "mlp.0"  # the layer that reads [proprioception, encoder features]


def encoder_at_zero(state: dict[str, torch.Tensor], activation: str) -> torch.Tensor:
    """The output of the MLP encoder stored in `state` (keys `encoder.net.<i>.*`) for an
    all-zero map. Raises if the encoder is not an MLP: the common start is a blind policy's."""
    layers = sorted(
        (int(m.group(1)), key)
        for key in state
        if (m := re.fullmatch(r"encoder\.net\.(\d+)\.weight", key))
    )
    if not layers:
        raise ValueError("algo.init_map_zero: the source checkpoint has no encoder")
    weights = [state[key] for _, key in layers]
    if any(w.dim() != 2 for w in weights):
        raise ValueError(
            "algo.init_map_zero: the source's encoder is not an MLP; the common start is a "
            "blind policy (curriculum=blind, encoder=mlp), whose encoder only saw zeros"
        )
    act = resolve_nn_activation(activation)
    h = torch.zeros(weights[0].shape[1], dtype=weights[0].dtype, device=weights[0].device)
    for k, ((_, key), weight) in enumerate(zip(layers, weights, strict=True)):
        h = weight @ h + state[key.replace(".weight", ".bias")]
        if k < len(layers) - 1:
            h = act(h)
    return h


def zero_map_state(
    source: dict[str, torch.Tensor], target: nn.Module, activation: str
) -> dict[str, torch.Tensor]:
    """A state dict for `target` (a PerceptiveMLPModel) from a blind model's `source`: every
    tensor but the encoder's and the first layer's as the source has it, the first layer with
    the source's zero-map features folded into its bias and zero weights on the features, the
    encoder as `target` was initialised. Raises naming the first tensor that does not fit."""
    if getattr(target, "is_recurrent", False):
        raise ValueError(
            "algo.init_map_zero: the common start is an MLP actor's; a recurrent actor "
            "(actor=lstm) cannot start from it: train it from scratch (algo.init_from='')"
        )
    own = target.state_dict()
    z0 = encoder_at_zero(source, activation)
    weight_key, bias_key = f"{FIRST_LAYER}.weight", f"{FIRST_LAYER}.bias"
    if weight_key not in own or weight_key not in source:
        raise ValueError(
            f"algo.init_map_zero: no '{weight_key}' in the model; the common start needs an "
            "MLP actor (actor=mlp)"
        )
    source_weight = source[weight_key]
    obs_dim = source_weight.shape[1] - z0.shape[0]
    target_weight = own[weight_key]
    if target_weight.shape[0] != source_weight.shape[0] or (
        target_weight.shape[1] - target._z_dim != obs_dim
    ):
        raise ValueError(
            f"algo.init_map_zero: '{weight_key}' is {tuple(target_weight.shape)} here and "
            f"{tuple(source_weight.shape)} in the source: the proprioception or the hidden "
            "sizes differ"
        )
    state = {}
    for key, value in own.items():
        if key.startswith("encoder."):
            state[key] = value
        elif key == weight_key:
            weight = torch.zeros_like(value)
            weight[:, :obs_dim] = source_weight[:, :obs_dim]
            state[key] = weight
        elif key == bias_key:
            state[key] = source[key] + source_weight[:, obs_dim:] @ z0
        elif key not in source or source[key].shape != value.shape:
            found = tuple(source[key].shape) if key in source else "missing"
            raise ValueError(
                f"algo.init_map_zero: '{key}' is {tuple(value.shape)} here, {found} in the source"
            )
        else:
            state[key] = source[key].clone()
    return state


NORMALISER = ("obs_normalizer._mean", "obs_normalizer._var", "obs_normalizer._std")


def widen_history(
    source: dict[str, torch.Tensor], target: nn.Module, frame_dim: int, frames: int
) -> dict[str, torch.Tensor]:
    """`source` (a model's state dict whose flat observation starts with its history, newest
    frame first) as if its history held `frames` frames of `frame_dim` values, as `target`'s
    does: older frames inserted after its own, with zero weights in the first layer and the
    newest frame's normaliser statistics. Raises naming the key when the models do not fit."""
    name = "algo.init_widen_history"
    if getattr(target, "is_recurrent", False):
        raise ValueError(f"{name}: a recurrent actor (actor=lstm) reads its history itself")
    mean = getattr(getattr(target, "obs_normalizer", None), "_mean", None)
    weight_key = f"{FIRST_LAYER}.weight"
    if mean is None or NORMALISER[0] not in source or weight_key not in source:
        raise ValueError(
            f"{name}: needs MLP models with observation normalisers "
            f"(algo.obs_normalization=true) and '{NORMALISER[0]}', '{weight_key}' in the source"
        )
    obs_dim, source_dim = mean.shape[-1], source[NORMALISER[0]].shape[-1]
    extra = obs_dim - source_dim
    own = frames - extra // frame_dim  # the source's history length
    if extra < 0 or extra % frame_dim or own < 1:
        raise ValueError(
            f"{name}: the source's observation is {source_dim} wide and this run's {obs_dim}: "
            f"not a shorter history of {frame_dim}-value frames "
            f"(task.observations.history={frames})"
        )
    cut = own * frame_dim
    state = dict(source)
    for key in NORMALISER:  # (1, obs) statistics
        stats = source[key]
        older = stats[:, :frame_dim].repeat(1, frames - own)
        state[key] = torch.cat([stats[:, :cut], older, stats[:, cut:]], dim=1)
    weight = source[weight_key]
    zeros = weight.new_zeros(weight.shape[0], extra)
    state[weight_key] = torch.cat([weight[:, :cut], zeros, weight[:, cut:]], dim=1)
    return state
