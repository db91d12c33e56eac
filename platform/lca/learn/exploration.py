"""An exploration schedule: a falling ceiling on the policy's action std.

A wide Gaussian finds stepping (a robot that is shaken must step to stay up); the same noise
makes every gait sloppy and costly once the penalties are the paper's. The ceiling falls
linearly from the initial std to `final_noise_std` at `noise_deadline` x max_iterations and
stays there; below it the std is rsl-rl's learned parameter.
"""

from __future__ import annotations

import math

from lca.config.schema import ActorConfig


def noise_ceiling(cfg: ActorConfig, iteration: int, total_iterations: int) -> float | None:
    """The cap on the action std at `iteration`, or None when the std is free."""
    if cfg.final_noise_std <= 0:
        return None
    end = max(math.ceil(cfg.noise_deadline * total_iterations), 1)
    progress = min(iteration / end, 1.0)
    return cfg.init_noise_std + (cfg.final_noise_std - cfg.init_noise_std) * progress


def apply_ceiling(actor, ceiling: float | None) -> None:
    """Clamp the actor's Gaussian std to `ceiling` (rsl-rl clamps to `std_range`)."""
    if ceiling is not None:
        actor.distribution.std_range[1] = float(ceiling)
        actor.distribution.log_std_range[1] = math.log(float(ceiling))
