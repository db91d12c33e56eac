"""Every lever of `python -m lca.bench levers` is a valid change of the time-to-walk recipe."""

from __future__ import annotations

import pytest

from lca.bench import walk
from lca.bench.levers import LEVERS
from lca.config import compose


@pytest.fixture(scope="module")
def recipe():
    return compose(walk.BASE)


@pytest.mark.parametrize("name", list(LEVERS))
def test_lever_composes_and_changes_the_recipe(name, recipe):
    what, overrides = LEVERS[name]
    assert what
    lever = compose([*walk.BASE, *overrides])
    assert (lever == recipe) == (overrides == [])
