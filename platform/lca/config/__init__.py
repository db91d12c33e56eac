"""Structured Hydra configs: schema dataclasses, validation and composition."""

from lca.config.compose import (
    ConfigError,
    compose,
    conf_dir,
    load_option,
    override_config,
    validate,
)
from lca.config.runtime import register_resolvers, resolve_device, set_torch_threads

register_resolvers()

__all__ = [
    "ConfigError",
    "compose",
    "conf_dir",
    "load_option",
    "override_config",
    "resolve_device",
    "set_torch_threads",
    "validate",
]
