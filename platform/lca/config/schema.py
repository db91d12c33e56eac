"""The root of the typed config, registered in Hydra's ConfigStore as `lca_schema`.

Each layer owns its groups' dataclasses, next to its code (`lca.sim.config`,
`lca.task.config`, `lca.learn.config`, `lca.evaluate.config`), and registers each with
`@group("<name>")`. This module never imports those layers: `LcaConfig` is assembled from
the registered groups the first time it is asked for, after the registries have loaded the
built-in variants (which import every layer's config module) and any plugin.

A typo in a key or a wrong type fails when Hydra composes. Value checks (ranges, sums) live
in `check()` methods that `lca.config.validate` runs right after composition.
"""

from __future__ import annotations

from dataclasses import dataclass, field, make_dataclass
from functools import cache

from hydra.core.config_store import ConfigStore
from omegaconf import DictConfig, OmegaConf

from lca.config.errors import ConfigValueError, require  # noqa: F401 (re-exported)
from lca.config.registry import load_plugins
from lca.paths import conf_dir

_GROUPS: dict[str, type] = {}


def group(name: str):
    """Class decorator: the dataclass of config group `name` (one per group)."""

    def register(cls: type) -> type:
        _GROUPS[name] = cls
        return cls

    return register


MATCH_KEYS = {"curriculum": "curriculum.name", "actor": "actor.kind", "encoder": "encoder.kind"}


@dataclass
class PolicyConfig:
    """The report's name for a run: set by a `conf/policy/*.yaml` option, or filled at
    composition from the policy file whose `match` equals the run (lca.config.policies)."""

    label: str = ""  # the table row, e.g. "Two-Stage MLP"; "" = not resolved yet
    row: int = 100  # position of the row in tables (smaller first)
    # which runs the label names: curriculum (name), actor and encoder (kinds); an absent key
    # matches any value (the blind policy's actor never sees the encoder)
    match: dict[str, str] = field(default_factory=dict)

    def check(self) -> None:
        unknown = sorted(set(self.match) - set(MATCH_KEYS))
        require(
            not unknown, "policy.match", f"unknown keys {unknown}; allowed: {sorted(MATCH_KEYS)}"
        )


@dataclass
class RootFields:
    seed: int = 0
    device: str = "auto"  # torch device: auto = cuda when available, else cpu
    torch_threads: int = 0  # 0 = torch default; sweeps set 1 per process
    # torch threads while collecting rollouts (small policy inferences next to mjbatch's
    # threads); 0 = the same as for the update
    collect_threads: int = 0
    runs_root: str = "runs"  # run store: one folder per run, named by its overrides
    force: bool = False  # re-run even when the run directory holds a completed run


def default_groups() -> list[str]:
    """The groups conf/config.yaml's defaults list chooses an option of (not `optional` ones)."""
    names = []
    for entry in OmegaConf.load(conf_dir() / "config.yaml").defaults:
        if isinstance(entry, DictConfig):
            names += [k for k in entry if not k.startswith("optional ")]
    return names


@cache
def root() -> type:
    """The root dataclass: the root's own fields, every registered group, then `policy`."""
    load_plugins()
    order = default_groups()  # the root's groups, as conf/config.yaml lists them
    missing = [name for name in order if name not in _GROUPS]
    if missing:
        raise RuntimeError(f"config groups {missing} were never registered (@group)")
    names = [*order, *(name for name in _GROUPS if name not in order)]
    fields = [(n, _GROUPS[n], field(default_factory=_GROUPS[n])) for n in names]
    fields.append(("policy", PolicyConfig, field(default_factory=PolicyConfig)))
    cls = make_dataclass("LcaConfig", fields, bases=(RootFields,))
    cls.__module__ = __name__  # pickle finds it through this module's __getattr__
    return cls


def register() -> None:
    ConfigStore.instance().store(name="lca_schema", node=root())


def __getattr__(name: str):
    if name == "LcaConfig":  # built on first use (pickle finds it here too)
        return root()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
