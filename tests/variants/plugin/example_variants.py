"""Variants added from outside the lca package, each one registration (plus one YAML under
conf/): a GRU actor, a `slopes` terrain tile, a reward term with a parameter and a reward
term that needs state the package's RobotState does not hold."""

from __future__ import annotations

import numpy as np

from lca.config.registry import ACTORS, REWARD_TERMS, TILES
from lca.learn.variants import ActorSpec

GRU = ActorSpec(
    "lca.learn.models:PerceptiveRNNModel",
    recurrent=True,
    exports=False,  # the platform's exporter handles LSTM state only: say so up front
    model_kwargs={"rnn_type": "gru"},
)
SLOPE_GRADE = 0.15  # rise per metre of a slopes tile, outwards from its spawn platform


def slopes_tile(lx, ly, cfg, difficulty, rng):
    """A square cone: flat on the spawn platform, rising SLOPE_GRADE per metre outwards."""
    ring = np.maximum(np.abs(lx), np.abs(ly)) - cfg.platform / 2
    return SLOPE_GRADE * np.clip(ring, 0.0, None), {"grade": SLOPE_GRADE}


def base_yaw_rate_l2(c, power: float = 2.0) -> np.ndarray:
    """|yaw rate|^power of the base: a turning penalty (power is a per-term parameter)."""
    return np.abs(c.state.base_ang_vel[:, 2]) ** power


def body_below(c, body: str = "torso_link", height: float = 0.9) -> np.ndarray:
    """How far a body sits below `height` m (world z): a quantity RobotState does not carry,
    read from the live physics (`c.sim`) without touching the package."""
    z = c.sim.data("xpos")[:, c.sim.body_id(body), 2]
    return np.clip(height - z, 0.0, None)


def register() -> None:
    ACTORS.register("gru", label="GRU")(GRU)
    TILES.register("slopes", label="Slopes")(slopes_tile)
    REWARD_TERMS.register("base_yaw_rate_l2")(base_yaw_rate_l2)
    REWARD_TERMS.register("body_below")(body_below)


def unregister() -> None:
    ACTORS.unregister("gru")
    TILES.unregister("slopes")
    REWARD_TERMS.unregister("base_yaw_rate_l2")
    REWARD_TERMS.unregister("body_below")


register()  # importing the module (LCA_PLUGINS or an entry point) registers the variants
