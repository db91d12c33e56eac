"""One definition of each per-step computation for NumPy arrays and torch tensors.

The task's terms and the terrain's height query take their array namespace from their
inputs (the array API, through array-api-compat) instead of importing NumPy, so the same
function runs on mjbatch's NumPy views and on torch tensors on the physics device
(sim.backend=warp on a GPU).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from array_api_compat import array_namespace, is_array_api_obj
from array_api_compat import device as device_of

# a NumPy array or a torch tensor: what the task's terms read and return
Array = Any


def namespace(*arrays: Array) -> Any:
    """The array API namespace of `arrays`: array_api_compat's numpy or torch."""
    return array_namespace(*arrays)


def arrays(*values: Any) -> tuple[Array, ...]:
    """`values` as arrays: NumPy float64 for Python numbers and sequences, arrays as they are."""
    return tuple(v if is_array_api_obj(v) else np.asarray(v, float) for v in values)


def like(value: Any, reference: Array) -> Array:
    """`value` (array or Python number) as an array of `reference`'s float dtype and device."""
    xp = array_namespace(reference)
    return xp.asarray(value, dtype=reference.dtype, device=device_of(reference))


def as_float(mask: Array, reference: Array) -> Array:
    """A boolean or integer array as `reference`'s float dtype."""
    return array_namespace(mask).astype(mask, reference.dtype)


def draw(rng: Any, low: float, high: float, shape: tuple, reference: Array) -> Array:
    """Uniform samples in [low, high) of `shape`: from a NumPy Generator for NumPy arrays,
    a torch.Generator on `reference`'s device (and in its dtype) for torch."""
    if isinstance(rng, np.random.Generator):
        return rng.uniform(low, high, shape)
    import torch

    unit = torch.rand(shape, generator=rng, dtype=reference.dtype, device=reference.device)
    return low + (high - low) * unit


def uniform(rng: Any, half_width: float, reference: Array) -> Array:
    """Uniform noise in [-half_width, half_width], shaped like `reference` (see `draw`)."""
    if isinstance(rng, np.random.Generator):
        return rng.uniform(-half_width, half_width, reference.shape)
    return draw(rng, -1.0, 1.0, tuple(reference.shape), reference) * half_width
