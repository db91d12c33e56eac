"""The built-in variants: importing these modules registers every tile, observation and
reward term, actor and encoder kind and evaluation terrain the package ships (see
lca.config.registry)."""

import lca.evaluate.terrains  # noqa: F401
import lca.learn.variants  # noqa: F401
import lca.sim.terrain  # noqa: F401
import lca.task.observations  # noqa: F401
import lca.task.rewards  # noqa: F401
