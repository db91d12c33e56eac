"""Evaluation terrains: what `eval.cells[*].terrain` may name, as tile mixtures with the
label the tables print. Every registered tile is also an evaluation terrain of its own
(`{tile: 1.0}`, labelled like the tile); the composites are registered here."""

from __future__ import annotations

from lca.config.registry import EVAL_TERRAINS, TILES, eval_terrain_names

# The paper's two table columns first: their order is the tables' column order.
EVAL_TERRAINS.register("stairs", label="Stairs")({"stairs_up": 0.5, "stairs_down": 0.5})
EVAL_TERRAINS.register("uneven", label="Uneven Terrain")({"uneven": 1.0})
EVAL_TERRAINS.register("mixed", label="Mixed")(
    {"flat": 0.25, "stairs_up": 0.25, "stairs_down": 0.25, "uneven": 0.25}
)


eval_terrains = eval_terrain_names  # every evaluation terrain, in table column order


def eval_mixture(name: str) -> dict[str, float]:
    if name in EVAL_TERRAINS:
        return dict(EVAL_TERRAINS[name])
    TILES.check(name, "evaluation terrain")
    return {name: 1.0}


def eval_label(name: str) -> str:
    if name in EVAL_TERRAINS:
        return EVAL_TERRAINS.label(name)
    return TILES.label(name)
