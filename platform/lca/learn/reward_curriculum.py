"""The reward curriculum: penalties grow from a fraction of the paper's weights to 1.

A young policy's penalties outweigh its rewards, so early on the cheapest way to a high
return is to fall at once, or to stand still. Scaling the negative contributions of the
configured terms (all by default) by `scale` < 1 lets tracking and the gait reward lead.
The scale rises with the mean episode length or linearly with the iteration, never falls,
and is exactly 1 from `deadline` x max_iterations on, so every run ends on the paper's
objective. A `cut` ends the ramp, the clip, the sigma and every open boost at once; a term's
own boost window (`boost_windows`) may open there, e.g. to make a fall dear for a while.
"""

from __future__ import annotations

import math

import numpy as np

from lca.task.config import RewardCurriculumConfig


class RewardCurriculum:
    def __init__(
        self, cfg: RewardCurriculumConfig, total_iterations: int, scale: float | None = None
    ):
        self.cfg = cfg
        self.total = total_iterations
        self.deadline = math.ceil(cfg.deadline * total_iterations) if cfg.enabled else 0
        self.cut = math.ceil(cfg.cut * total_iterations)
        # the first iteration of the table's weights, unclipped (late boosts may follow)
        self.end = min(self.deadline, self.cut)
        self.step = (1.0 - cfg.penalty_start) / max(cfg.ramp * total_iterations, 1.0)
        start = cfg.penalty_start if cfg.enabled else 1.0
        self.scale = float(start if scale is None else scale)
        self.iteration = 0
        # the iterations [start, end) of a late boost window; None: boosts follow the penalties
        self.boost_window = self._iterations(cfg.boost_window)
        self.windows = {k: self._iterations(w) for k, w in cfg.boost_windows.items()}

    def _iterations(self, window: list[float]) -> tuple[int, int] | None:
        return tuple(math.ceil(f * self.total) for f in window) if window else None

    def target(self, iteration: int, episode_fraction: float) -> float:
        """Scale asked for by the mean episode length (fraction of the maximum) or, with
        `by: iterations`, by the iteration (a linear ramp to the deadline)."""
        c = self.cfg
        if c.by == "iterations":
            progress = iteration / max(self.deadline, 1)
        elif np.isfinite(episode_fraction):
            progress = (episode_fraction - c.length_start) / (c.length_end - c.length_start)
        else:
            progress = 0.0
        return float(c.penalty_start + (1.0 - c.penalty_start) * np.clip(progress, 0, 1))

    def update(
        self, iteration: int, episode_fraction: float, tracking: float = float("nan")
    ) -> float:
        """The scale for `iteration`, given the latest mean episode length fraction and, for
        `by: tracking`, the tracking progress 1 - |u - v| / |u| of the last rollout."""
        c = self.cfg
        self.iteration = iteration
        if not c.enabled or iteration >= self.end:
            self.scale = 1.0
        elif c.by == "tracking":
            if episode_fraction >= c.length_start and tracking >= c.gate:
                self.scale = max(self.scale, min(c.hold, self.scale + self.step))
        else:
            self.scale = max(self.scale, min(c.hold, self.target(iteration, episode_fraction)))
        if c.enabled and c.hold < 1.0:
            self.scale = max(self.scale, self.release(iteration))
        return min(self.scale, 1.0)

    def release(self, iteration: int) -> float:
        """The held scale's ramp: `hold` until hold_until x max_iterations, then linear to 1
        at the deadline."""
        c = self.cfg
        start = min(math.ceil(c.hold_until * self.total), self.deadline - 1)
        progress = np.clip((iteration - start) / max(self.deadline - start, 1), 0.0, 1.0)
        return float(c.hold + (1.0 - c.hold) * progress) if iteration > start else 0.0

    @property
    def only_positive(self) -> bool:
        return bool(self.cfg.enabled and self.cfg.only_positive and self.scale < 1.0)

    @property
    def progress(self) -> float:
        """0 at the start of the ramp, 1 at the paper's weights."""
        start = self.cfg.penalty_start if self.cfg.enabled else 0.0
        return 1.0 if start >= 1.0 else (self.scale - start) / (1.0 - start)

    @property
    def done(self) -> bool:
        """True once the objective is the paper's: full penalties, no clipping, no boost."""
        return (
            self.scale >= 1.0
            and not self.only_positive
            and not self.boosts
            and self.sigma_scale == 1.0
        )

    def _boost_left(self, window: tuple[int, int] | None) -> float:
        """How much of a boost's shaping is left: 1 at the start (of its window, if any),
        falling to 0 once the penalties are the table's (at the window's end); 0 from the
        cut on for a window opened before it."""
        it = self.iteration
        if not self.cfg.enabled:
            return 0.0
        if window:
            start, end = window
            if not start <= it < end or start < self.cut <= it:
                return 0.0
            return 1.0 - (it - start) / max(end - start, 1)
        if self.scale >= 1.0 and not self.only_positive:
            return 0.0
        return 1.0 - self.progress

    @property
    def boosts(self) -> dict[str, float]:
        """Factors on the boosted terms' weights: the configured ones at the start (of their
        window, if any), none left once the penalties are the table's (at its end)."""
        out = {}
        for name, factor in self.cfg.boost.items():
            left = self._boost_left(self.windows.get(name, self.boost_window))
            if left > 0.0:
                out[name] = 1.0 + (float(factor) - 1.0) * left
        return out

    @property
    def sigma_scale(self) -> float:
        """Factor on the tracking kernels' sigma: the configured one at the start, 1 (the
        paper's) as the boosts end."""
        return 1.0 + (float(self.cfg.sigma_scale) - 1.0) * self._boost_left(self.boost_window)

    @property
    def shaping(self) -> tuple[float, bool, dict[str, float], float]:
        """What the env applies: (penalty scale, clipping, boosts, sigma scale)."""
        return self.scale, self.only_positive, self.boosts, self.sigma_scale
