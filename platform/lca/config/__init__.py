"""Structured Hydra configs: schema dataclasses, validation and composition."""

from lca.config.compose import ConfigError, compose, conf_dir, validate
from lca.config.schema import LcaConfig

__all__ = ["ConfigError", "LcaConfig", "compose", "conf_dir", "validate"]
