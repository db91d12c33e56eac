"""Perception curricula: when the actor's heightmap is on.

blind: never; one: from the first iteration; two: after `perception_from` of the iterations.
Every curriculum runs the same total iterations and the same networks throughout; in
`two` the optimizer state (Adam moments) carries over the switch, as one continuous run.
"""

from __future__ import annotations

import math

from lca.learn.config import CurriculumConfig


def switch_iteration(cfg: CurriculumConfig, total_iterations: int) -> int:
    """First iteration with perception on (== total_iterations for a blind run)."""
    return min(total_iterations, math.ceil(cfg.perception_from * total_iterations))


def perception_on(cfg: CurriculumConfig, iteration: int, total_iterations: int) -> bool:
    return iteration >= switch_iteration(cfg, total_iterations)


def stage_name(cfg: CurriculumConfig, iteration: int, total_iterations: int) -> str:
    return "perception" if perception_on(cfg, iteration, total_iterations) else "blind"
