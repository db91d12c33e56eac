"""Small timing helpers shared by the benchmarks."""

from __future__ import annotations

import time
from collections.abc import Callable


def rate(step: Callable[[], int], min_seconds: float, min_calls: int = 3) -> float:
    """Units per second of `step()` (which returns the units it did), over >= min_seconds."""
    units, calls = 0, 0
    start = time.perf_counter()
    while True:
        units += step()
        calls += 1
        elapsed = time.perf_counter() - start
        if calls >= min_calls and elapsed >= min_seconds:
            return units / elapsed


def median_rate(step: Callable[[], int], repeats: int, min_seconds: float) -> float:
    rates = sorted(rate(step, min_seconds) for _ in range(repeats))
    return rates[len(rates) // 2]


def split_params(overrides: list[str], defaults: dict[str, str]) -> tuple[dict, list[str]]:
    """The benchmark's own `key=value` parameters (those in `defaults`, which fill the
    missing ones) and the rest of `overrides` (Hydra overrides), in order."""
    params, extra = dict(defaults), []
    for item in overrides:
        key, _, value = item.partition("=")
        if key in defaults:
            params[key] = value
        else:
            extra.append(item)
    return params, extra
