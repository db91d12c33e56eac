"""The example variants are registered for these tests only, and removed afterwards, so the
rest of the suite sees the built-ins alone."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

PLUGIN = Path(__file__).resolve().parent / "plugin"


@pytest.fixture
def example_variants():
    sys.path.insert(0, str(PLUGIN))
    try:
        import example_variants

        example_variants.register()
        yield example_variants
        example_variants.unregister()
    finally:
        sys.path.remove(str(PLUGIN))
