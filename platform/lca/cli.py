"""Command-line helpers shared by the `python -m lca.*` entry points."""

from __future__ import annotations


def split_option(args: list[str], key: str) -> tuple[list[str], list[str]]:
    """(values of every `key=value` in `args`, the other args in order)."""
    prefix = f"{key}="
    values = [a[len(prefix) :] for a in args if a.startswith(prefix)]
    return values, [a for a in args if not a.startswith(prefix)]
