"""Compose the project's Hydra config outside `@hydra.main` and check its values."""

from __future__ import annotations

import contextlib
from functools import cache

from hydra import compose as hydra_compose
from hydra import initialize_config_dir
from hydra.core.global_hydra import GlobalHydra
from hydra.core.override_parser.overrides_parser import OverridesParser
from omegaconf import DictConfig, OmegaConf

from lca.config import schema
from lca.config.errors import require
from lca.config.policies import label_policy
from lca.config.schema import ConfigValueError
from lca.paths import conf_dir

ConfigError = ConfigValueError


def _reject_unknown_keys(cfg: DictConfig) -> None:
    """A `+key=value` append slips past Hydra's struct check; the schema must still hold.
    Every key under a group's dataclass must be one of its fields (free-keyed tables such as
    `task.rewards` or `terrain.mixture` take any name; their checks judge the names)."""
    bad = _unknown(cfg, _schema_node(), "")
    if bad:
        raise ConfigError(f"{bad[0]}: not in the schema (no such field)")


@cache
def _schema_node() -> DictConfig:
    return OmegaConf.structured(schema.root())


def _unknown(node: DictConfig, typed: DictConfig, prefix: str) -> list[str]:
    fixed = OmegaConf.get_type(typed) not in (dict, None)
    fields = set(typed.keys())  # `in` on a DictConfig skips MISSING fields
    out = []
    for key in list(node.keys()):
        if key == "hydra":
            continue
        path = f"{prefix}{key}"
        if key not in fields:
            out += [path] if fixed else []
            continue
        child, schema_child = node._get_node(key), typed._get_node(key)
        if isinstance(child, DictConfig) and isinstance(schema_child, DictConfig):
            out += _unknown(child, schema_child, f"{path}.")
    return out


def validate(cfg: DictConfig) -> None:
    """Check keys against the schema, then run every group's `check()`; raises ConfigError
    naming the bad key."""
    _reject_unknown_keys(cfg)
    obj = OmegaConf.to_object(cfg)
    for group in vars(obj).values():
        check = getattr(group, "check", None)
        if callable(check):
            check()
    require(
        obj.sim.backend == "mjbatch" or obj.perception.source == "privileged",
        "perception.source",
        "deployment casts its camera rays with sim.backend=mjbatch only",
    )


def load_option(group: str, name: str) -> DictConfig:
    """One option of a config group (conf/<group>/<name>.yaml) checked against its schema.
    Unlike `compose`, this also works inside a running Hydra app."""
    path = conf_dir() / group / f"{name}.yaml"
    if not path.exists():
        options = sorted(p.stem for p in path.parent.glob("*.yaml"))
        raise ConfigError(f"{group}: unknown option '{name}'; allowed: {options}")
    typed = OmegaConf.structured(schema.LcaConfig)[group]
    return OmegaConf.merge(typed, OmegaConf.load(path))


def compose(overrides: list[str] | None = None, config_name: str = "config") -> DictConfig:
    """Compose `conf/config.yaml` with Hydra overrides, then validate it."""
    schema.register()
    with (
        _outside_running_app(),
        initialize_config_dir(config_dir=str(conf_dir()), version_base="1.3"),
    ):
        cfg = hydra_compose(config_name=config_name, overrides=list(overrides or []))
    validate(cfg)
    label_policy(cfg, searchpath(overrides or []))
    return cfg


@contextlib.contextmanager
def _outside_running_app():
    """Inside `@hydra.main` (run.py's job: its provenance composes the paper profile) the
    global Hydra is the app's: set it aside for this composition, then give it back."""
    hydra = GlobalHydra.instance().hydra
    GlobalHydra.instance().clear()
    try:
        yield
    finally:
        GlobalHydra.instance().hydra = hydra


def searchpath(overrides: list[str]) -> list[str]:
    """The `hydra.searchpath=[...]` folders named in `overrides` (none: [])."""
    for parsed in OverridesParser.create().parse_overrides(list(overrides)):
        if parsed.key_or_group == "hydra.searchpath":
            return [str(v) for v in parsed.value()]
    return []


def _delta(before, after):
    """The leaves of `after` that differ from `before` (nested dicts; lists compared whole)."""
    if isinstance(before, dict) and isinstance(after, dict):
        out = {}
        for key, value in after.items():
            if key not in before:
                out[key] = value
            else:
                sub = _delta(before[key], value)
                if sub is not _SAME:
                    out[key] = sub
        return out or _SAME
    return _SAME if before == after else after


_SAME = object()


def _removed(before, after, path: tuple = ()) -> list[tuple]:
    """Paths of the keys of `before` that `after` no longer has (e.g. a mixture's tiles)."""
    if not (isinstance(before, dict) and isinstance(after, dict)):
        return []
    out = [(*path, k) for k in before if k not in after]
    for k in before:
        if k in after:
            out += _removed(before[k], after[k], (*path, k))
    return out


def override_config(
    base: DictConfig, overrides: list[str], base_overrides: list[str] | None = None
) -> DictConfig:
    """`base` (a run's resolved config) with `overrides` applied exactly as `run.py` would
    apply them, group options (`scale=smoke`, `difficulty=hard`) included: the change that
    the overrides make to the composition of `base_overrides` (the run's own overrides) is
    merged onto `base`. Raises ConfigError naming a bad key or option."""
    if not overrides:
        return base
    common = list(base_overrides or [])
    try:
        before = OmegaConf.to_container(compose(common), resolve=True)
    except Exception:  # the run's overrides no longer compose (conf/ changed): start plain
        before, common = OmegaConf.to_container(compose([]), resolve=True), []
    after = OmegaConf.to_container(compose([*common, *overrides]), resolve=True)
    change = _delta(before, after)
    gone = _removed(before, after)
    if change is _SAME and not gone:
        return base
    merged = OmegaConf.merge(base, {} if change is _SAME else change)
    for *parent, key in gone:
        node = OmegaConf.select(merged, ".".join(parent)) if parent else merged
        if node is not None and key in node:
            del node[key]
    validate(merged)
    return merged
