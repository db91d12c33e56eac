"""The built-ins: importing these modules registers every config group (each layer's
`config` module), tile, observation and reward term, actor and encoder kind and evaluation
terrain the package ships (see lca.config.registry and lca.config.schema)."""

import lca.evaluate.config  # noqa: F401
import lca.evaluate.terrains  # noqa: F401
import lca.learn.config  # noqa: F401
import lca.learn.variants  # noqa: F401
import lca.sim.config  # noqa: F401
import lca.sim.terrain  # noqa: F401
import lca.task.config  # noqa: F401
import lca.task.observations  # noqa: F401
import lca.task.rewards  # noqa: F401
