"""Every lever of `python -m lca.bench levers` is a valid change of the time-to-walk recipe."""

from __future__ import annotations

import pytest

from lca.bench import walk
from lca.bench.levers import LEVERS, write_markdown
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


def test_levers_table_names_its_budget_and_every_lever(tmp_path):
    result = {
        "what": "w",
        "success": 100.0,
        "track_cm_s": 34.3,
        "still_cm_s": 10.7,
        "env_steps": 2_002_944,
        "steps_per_s": 2237.0,
        "time_to_walk_s": None,
    }
    physics = {"plane (default)": {"overrides": [], "steps_per_s": 2000.0}}
    out = tmp_path / "levers.md"
    write_markdown({"recipe": result, "no_symmetry": result}, physics, "326-iteration", out)
    text = out.read_text()
    assert text.startswith("# Learning levers at a 326-iteration budget")
    assert "| no_symmetry | w | 100.0 | 34.3 | 10.7 | 2.00 | 2,237 | - |" in text
