"""The config layer's error (a bad value, its message starting with the full key) and the
small checks every group's `check()` uses."""

from __future__ import annotations


class ConfigValueError(ValueError):
    """A config value outside its allowed range; the message starts with the full key."""


def require(ok: bool, key: str, message: str) -> None:
    if not ok:
        raise ConfigValueError(f"{key}: {message}")


def check_range(key: str, lo_hi: list[float], low: float = 0.0) -> None:
    require(len(lo_hi) == 2, key, f"expected [low, high], got {list(lo_hi)}")
    require(lo_hi[0] >= low, key, f"must be >= {low}, got {list(lo_hi)}")
    require(lo_hi[0] <= lo_hi[1], key, f"low must not exceed high, got {list(lo_hi)}")
