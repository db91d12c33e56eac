"""One set of defaults: every value a group's default option (conf/<group>/<default>.yaml)
sets equals the schema dataclass's default, so the code and the YAML cannot drift apart."""

from __future__ import annotations

import pytest
from omegaconf import OmegaConf

from lca.config import schema
from lca.paths import conf_dir

DEFAULTS = OmegaConf.load(conf_dir() / "config.yaml").defaults


def default_options() -> list[tuple[str, str]]:
    options = []
    for entry in DEFAULTS:
        if isinstance(entry, str) or entry is None:
            continue
        ((group, name),) = OmegaConf.to_container(entry).items()
        if name is not None and not group.startswith("optional"):
            options.append((group, name))
    return options


def disagreements(code, yaml, key: str) -> list[str]:
    if isinstance(yaml, dict):
        out = []
        for k, v in yaml.items():
            if isinstance(code, dict) and k in code:
                out += disagreements(code[k], v, f"{key}.{k}")
        return out
    if isinstance(yaml, list) and isinstance(code, list) and len(yaml) == len(code):
        out = []
        for i, (c, y) in enumerate(zip(code, yaml, strict=True)):
            out += disagreements(c, y, f"{key}[{i}]")
        return out
    if code == "???":  # MISSING in the schema: the YAML is the one source
        return []
    same = code == yaml or (
        isinstance(code, int | float) and isinstance(yaml, int | float) and abs(code - yaml) < 1e-12
    )
    return [] if same else [f"{key}: code {code!r} != yaml {yaml!r}"]


def test_the_default_options_are_found() -> None:
    groups = dict(default_options())
    assert groups["terrain"] == "mixed" and groups["scale"] == "cpu" and len(groups) >= 14


@pytest.mark.parametrize(("group", "name"), default_options())
def test_default_option_equals_the_schema_defaults(group: str, name: str) -> None:
    code = OmegaConf.to_container(OmegaConf.structured(schema.LcaConfig), resolve=False)
    yaml = OmegaConf.to_container(OmegaConf.load(conf_dir() / group / f"{name}.yaml"))
    yaml.pop("defaults", None)
    if group == "scale":  # a global package: its other keys are the scale's deliberate changes
        yaml = yaml["scale"]
    assert disagreements(code[group], yaml, group) == []


def test_a_drifted_default_is_caught() -> None:
    assert disagreements({"a": {"b": [8, 16]}}, {"a": {"b": [16, 16]}}, "x") == [
        "x.a.b[0]: code 8 != yaml 16"
    ]
    assert disagreements({"a": [1]}, {"a": [1, 2]}, "x") == ["x.a: code [1] != yaml [1, 2]"]
