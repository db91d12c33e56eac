"""Where the project's folders live: the root with `conf/`, `assets/` and `reports/`.

The root is $LCA_ROOT if set, else the checkout this package was imported from (an editable
install), else the working directory. An installed wheel therefore works from any folder that
holds `conf/` (a clone, or a copy of its `conf/` and `assets/`), or with LCA_ROOT pointing at one.
"""

from __future__ import annotations

import os
from pathlib import Path

CHECKOUT = Path(__file__).resolve().parents[2]  # platform/lca/paths.py -> the repository


def root() -> Path:
    env = os.environ.get("LCA_ROOT")
    if env:
        return Path(env).resolve()
    if (CHECKOUT / "conf").is_dir():
        return CHECKOUT
    return Path.cwd()


def conf_dir() -> Path:
    """The Hydra config folder: $LCA_CONF_DIR, else `<root>/conf`."""
    env = os.environ.get("LCA_CONF_DIR")
    path = Path(env).resolve() if env else root() / "conf"
    if not path.is_dir():
        raise FileNotFoundError(
            f"no config folder at {path}: run from a clone of lca, or set LCA_ROOT (or "
            "LCA_CONF_DIR) to the folder that holds conf/"
        )
    return path


def assets_dir() -> Path:
    return root() / "assets"


def reports_dir() -> Path:
    return root() / "reports"
