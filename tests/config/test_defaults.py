"""One source of defaults. Every value is set in exactly one place: the group's dataclass
(lca.<layer>.config), or, for the tables a dataclass leaves MISSING or empty (observation and
reward terms, the robot's actuators and home pose, a terrain's mixture), the group's default
option in conf/. No default option restates a dataclass default, so the two cannot drift
apart; the composed default config is exactly the dataclasses plus those tables."""

from __future__ import annotations

import pytest
from omegaconf import OmegaConf

from lca.config import compose, schema
from lca.paths import conf_dir

DEFAULTS = OmegaConf.load(conf_dir() / "config.yaml").defaults
UNSET = ("???", {}, [], None)  # a dataclass field whose value only the YAML gives


def default_options() -> list[tuple[str, str]]:
    options = []
    for entry in DEFAULTS:
        if isinstance(entry, str) or entry is None:
            continue
        ((group, name),) = OmegaConf.to_container(entry).items()
        if name is not None and not group.startswith("optional"):
            options.append((group, name))
    return options


def restated(code, yaml, key: str) -> list[str]:
    """The leaves `yaml` sets that the dataclass (`code`) already sets."""
    if isinstance(yaml, dict) and isinstance(code, dict) and code not in UNSET:
        out = []
        for k, v in yaml.items():
            out += restated(code[k], v, f"{key}.{k}") if k in code else []
        return out
    return [] if code in UNSET else [f"{key} = {yaml!r} (the dataclass says {code!r})"]


def option_values(group: str, name: str) -> dict:
    yaml = OmegaConf.to_container(OmegaConf.load(conf_dir() / group / f"{name}.yaml")) or {}
    yaml.pop("defaults", None)
    if group == "scale":  # a global package: its keys are the scale's changes to other groups
        yaml = yaml.get("scale", {})
    return yaml


def code_defaults() -> dict:
    return OmegaConf.to_container(OmegaConf.structured(schema.root()), resolve=False)


def test_the_default_options_are_found() -> None:
    groups = dict(default_options())
    assert groups["terrain"] == "mixed" and groups["scale"] == "cpu" and len(groups) >= 14


@pytest.mark.parametrize(("group", "name"), default_options())
def test_no_default_option_restates_the_dataclass(group: str, name: str) -> None:
    assert restated(code_defaults()[group], option_values(group, name), group) == []


def test_the_root_config_restates_no_default() -> None:
    root = OmegaConf.to_container(OmegaConf.load(conf_dir() / "config.yaml"))
    own = {k: v for k, v in root.items() if k not in ("defaults", "hydra")}
    assert restated(code_defaults(), own, "config") == []


def test_the_composed_defaults_are_the_dataclasses_plus_the_yaml_tables() -> None:
    expected = OmegaConf.structured(schema.root())
    for group, name in default_options():
        if group != "scale":
            expected[group] = OmegaConf.merge(expected[group], option_values(group, name))
    scale = OmegaConf.load(conf_dir() / "scale" / "cpu.yaml")  # the default scale's changes
    scale.pop("defaults", None)
    expected = OmegaConf.merge(expected, scale)
    composed = compose([])
    got = OmegaConf.to_container(composed, resolve=True)
    want = OmegaConf.to_container(expected, resolve=True)
    want["policy"] = got["policy"]  # filled at composition from conf/policy (test_policies)
    assert got == want


def test_a_restated_default_is_caught() -> None:
    assert restated({"a": {"b": [8, 16]}}, {"a": {"b": [8, 16]}}, "x") == [
        "x.a.b = [8, 16] (the dataclass says [8, 16])"
    ]
    assert restated({"a": "???", "m": {}}, {"a": [1], "m": {"flat": 1.0}}, "x") == []
