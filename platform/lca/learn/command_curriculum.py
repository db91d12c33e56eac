"""The command curriculum: early commands ask the robot to walk, not to stand.

Under the full command range most commands are slow, and a robot standing still already
earns most of the tracking reward. A floor on the planar speed (slower commands are scaled up
to it) makes walking pay from the first iteration; it falls linearly to 0 at `deadline` x
max_iterations, after which commands are drawn from the configured range alone.

The ranges can also widen, from `widen_from` (e.g. forward only) to the configured ones by
the same deadline. A gait found under forward-only commands then follows its commands
(walking forward whatever it is told does not pay once backward and turning commands come),
before the full range asks for the rest.
"""

from __future__ import annotations

import math

from lca.task.config import CommandConfig, CommandCurriculumConfig

RANGE_KEYS = ("lin_vel_x", "lin_vel_y", "ang_vel_z", "standing_fraction")


class CommandCurriculum:
    def __init__(self, cfg: CommandCurriculumConfig, total_iterations: int):
        self.cfg = cfg
        self.deadline = math.ceil(cfg.deadline * total_iterations) if cfg.enabled else 0

    def floor(self, iteration: int) -> float:
        """Minimum planar command speed (m/s) at `iteration`; 0 from the deadline on."""
        if not self.cfg.enabled or iteration >= self.deadline:
            return 0.0
        return self.cfg.min_speed * (1.0 - iteration / self.deadline)

    def ranges(self, iteration: int, target: CommandConfig) -> dict:
        """The widened fields at `iteration` (key -> [low, high] or the standing fraction),
        each linear from `widen_from` to `target`'s; {} once the deadline is passed."""
        if not self.cfg.enabled or iteration >= self.deadline:
            return {}
        t = iteration / self.deadline
        out = {}
        for key in RANGE_KEYS:
            start = getattr(self.cfg.widen_from, key)
            if start is None:
                continue
            end = getattr(target, key)
            if key == "standing_fraction":
                out[key] = float(start + (end - start) * t)
            else:
                out[key] = [float(a + (b - a) * t) for a, b in zip(start, end, strict=True)]
        return out
