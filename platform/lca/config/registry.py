"""The named variants each layer contributes, and the checks of config names against them.

Layers register at import time, next to their code: terrain tiles (`sim.terrain`), reward
terms (`task.rewards`), actor and encoder kinds (`learn.variants`), evaluation terrains
(`evaluate.protocol`). The config layer never imports those layers: a registry loads the
modules named by the `lca.plugins` entry points (the package's own, `lca.variants`, lists the
built-ins) the first time it is read. Code outside the package adds a variant the same way:
`TILES.register("slopes", label="Slopes")(slopes_tile)` in its own module, loaded through an
`lca.plugins` entry point, or named in $LCA_PLUGINS (comma-separated module names).
"""

from __future__ import annotations

import importlib
import os
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from importlib.metadata import entry_points
from typing import Any

from lca.config.errors import ConfigValueError

BUILTINS = "lca.variants"
_loaded = False


def load_plugins() -> None:
    """Import the built-in variants, every `lca.plugins` entry point and the modules named in
    $LCA_PLUGINS, once."""
    global _loaded
    if _loaded:
        return
    _loaded = True
    importlib.import_module(BUILTINS)
    for point in entry_points(group="lca.plugins"):
        if point.value != BUILTINS:
            point.load()
    for name in filter(None, os.environ.get("LCA_PLUGINS", "").split(",")):
        importlib.import_module(name.strip())


@dataclass
class Entry:
    name: str
    value: Any
    label: str
    meta: dict = field(default_factory=dict)


class Registry:
    """Names -> registered values, in registration order (which is also report order)."""

    def __init__(self, what: str) -> None:
        self.what = what
        self._entries: dict[str, Entry] = {}

    def register(self, name: str, label: str | None = None, **meta: Any) -> Callable:
        """Decorator: `@REGISTRY.register("name", label="Name")`. Re-registering a name
        replaces it (a plugin may override a built-in)."""

        def add(value: Any) -> Any:
            self._entries[name] = Entry(name, value, label or name, meta)
            return value

        return add

    def unregister(self, name: str) -> None:
        self._entries.pop(name, None)

    def names(self) -> tuple[str, ...]:
        load_plugins()
        return tuple(self._entries)

    def entry(self, name: str, key: str | None = None) -> Entry:
        load_plugins()
        if name not in self._entries:
            where = f"{key}: " if key else ""
            raise ConfigValueError(
                f"{where}unknown {self.what} '{name}'; allowed: {list(self._entries)}"
            )
        return self._entries[name]

    def __getitem__(self, name: str) -> Any:
        return self.entry(name).value

    def __contains__(self, name: object) -> bool:
        load_plugins()
        return name in self._entries

    def __iter__(self) -> Iterator[str]:
        return iter(self.names())

    def items(self) -> list[tuple[str, Any]]:
        load_plugins()
        return [(n, e.value) for n, e in self._entries.items()]

    def label(self, name: str) -> str:
        return self.entry(name).label

    def check(self, name: str, key: str) -> None:
        self.entry(name, key)


TILES = Registry("terrain tile")  # name -> f(lx, ly, terrain, difficulty, rng) -> (heights, params)
EVAL_TERRAINS = Registry("evaluation terrain")  # name -> {tile: weight}
OBS_TERMS = Registry("observation term")  # name -> ObsTerm(dim, value) (task.observations)
REWARD_TERMS = Registry("reward term")  # name -> f(RewardContext) -> (N,) unweighted
ACTORS = Registry("actor kind")  # name -> ActorSpec (learn.variants)
ENCODERS = Registry("encoder kind")  # name -> rsl-rl encoder cfg "type"


def eval_terrain_names() -> list[str]:
    """What an evaluation cell may name, in table column order: the registered evaluation
    terrains, then every tile not among them (a tile alone is a terrain of its own)."""
    composites = EVAL_TERRAINS.names()
    return [*composites, *(t for t in TILES.names() if t not in composites)]
