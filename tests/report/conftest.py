"""The hand-made run store and its report, built once per session."""

from __future__ import annotations

from pathlib import Path

import pytest

from lca.report.build import build_report

from .helpers import build_fixture_store


@pytest.fixture(scope="session")
def fixture_store(tmp_path_factory) -> Path:
    return build_fixture_store(tmp_path_factory.mktemp("report") / "store")


@pytest.fixture(scope="session")
def fixture_report(fixture_store: Path) -> Path:
    """`build_report([store], store/report)`: the report folder."""
    out = fixture_store / "report"
    index = build_report([fixture_store], out)
    assert index == out / "index.html"
    return out
