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
    """The array API namespace of `arrays`: NumPy itself for NumPy arrays (NumPy 2 implements
    the standard; array_api_compat's wrappers of it cost ~1 ms a step in Python), else
    array_api_compat's torch."""
    if all(type(a) is np.ndarray for a in arrays):
        return np
    return array_namespace(*arrays)


def arrays(*values: Any) -> tuple[Array, ...]:
    """`values` as arrays: NumPy float64 for Python numbers and sequences, arrays as they are."""
    return tuple(v if is_array_api_obj(v) else np.asarray(v, float) for v in values)


def like(value: Any, reference: Array) -> Array:
    """`value` (array or Python number) as an array of `reference`'s float dtype and device."""
    xp = namespace(reference)
    return xp.asarray(value, dtype=reference.dtype, device=device_of(reference))


def as_float(mask: Array, reference: Array) -> Array:
    """A boolean or integer array as `reference`'s float dtype."""
    return namespace(mask).astype(mask, reference.dtype)


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
    return draw(rng, -half_width, half_width, tuple(reference.shape), reference)


def zeros(shape: Any, reference: Array, dtype: Any = None) -> Array:
    """Zeros of `shape` in `reference`'s array type and device (its dtype unless given)."""
    xp = namespace(reference)
    return xp.zeros(shape, dtype=dtype or reference.dtype, device=device_of(reference))


def generator(seed: int, reference: Array) -> Any:
    """A random stream for arrays like `reference`: a NumPy Generator, or a torch.Generator on
    the tensor's device."""
    if isinstance(reference, np.ndarray):
        return np.random.default_rng(seed)
    import torch

    return torch.Generator(reference.device).manual_seed(seed)


def rng_state(rng: Any) -> Any:
    """A generator's state, picklable (see `set_rng_state`)."""
    return rng.bit_generator.state if isinstance(rng, np.random.Generator) else rng.get_state()


def set_rng_state(rng: Any, state: Any) -> None:
    if isinstance(rng, np.random.Generator):
        rng.bit_generator.state = state
    else:
        rng.set_state(state)


def copy_of(value: Array) -> Array:
    """A copy in the same array type and device."""
    return namespace(value).asarray(value, copy=True)


def to_numpy(value: Any) -> np.ndarray:
    """A NumPy array of `value` (a tensor is brought to the host; a NumPy array is as is)."""
    if isinstance(value, np.ndarray):
        return value
    if hasattr(value, "detach"):
        return value.detach().cpu().numpy()
    return np.asarray(value)
