"""The command curriculum: early commands ask the robot to walk, not to stand.

Under the full command range most commands are slow, and a robot standing still already
earns most of the tracking reward. A floor on the planar speed (slower commands are scaled up
to it) makes walking pay from the first iteration; it falls linearly to 0 at `deadline` x
max_iterations, after which commands are drawn from the configured range alone.
"""

from __future__ import annotations

import math

from lca.task.config import CommandCurriculumConfig


class CommandCurriculum:
    def __init__(self, cfg: CommandCurriculumConfig, total_iterations: int):
        self.cfg = cfg
        self.deadline = math.ceil(cfg.deadline * total_iterations) if cfg.enabled else 0

    def floor(self, iteration: int) -> float:
        """Minimum planar command speed (m/s) at `iteration`; 0 from the deadline on."""
        if not self.cfg.enabled or iteration >= self.deadline:
            return 0.0
        return self.cfg.min_speed * (1.0 - iteration / self.deadline)
