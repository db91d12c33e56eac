"""Typed schema of every config group; registered in Hydra's ConfigStore as `lca_schema`.

A typo in a key or a wrong type fails when Hydra composes. Value checks (ranges, sums) live
in `check()` methods that `lca.config.validate` runs right after composition. Each stage's
groups live in their own module (sim_schema, task_schema, ...); this one assembles the root.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from hydra.core.config_store import ConfigStore

from lca.config.errors import ConfigValueError  # noqa: F401 (re-exported)
from lca.config.eval_schema import (  # noqa: F401 (re-exported)
    EvalCell,
    EvalConfig,
)
from lca.config.hardware_schema import (  # noqa: F401 (re-exported)
    HARDWARE_TASKS,
    CameraConfig,
    HardwareConfig,
    HingedPlankConfig,
    PerceptionConfig,
    SoftMatConfig,
    StairTaskConfig,
)
from lca.config.learn_schema import (  # noqa: F401 (re-exported)
    ActorConfig,
    AlgoConfig,
    CurriculumConfig,
    EncoderConfig,
    LoggerConfig,
    PolicyConfig,
    ScaleConfig,
)
from lca.config.sim_schema import (  # noqa: F401 (re-exported)
    ActuatorGroup,
    DifficultyConfig,
    RobotConfig,
    SimConfig,
    TerrainConfig,
)
from lca.config.task_schema import (  # noqa: F401 (re-exported)
    CommandConfig,
    CommandCurriculumConfig,
    ObservationConfig,
    RandomizationConfig,
    ResetConfig,
    RewardCurriculumConfig,
    RewardParams,
    TaskConfig,
    TerminationConfig,
)


@dataclass
class LcaConfig:
    seed: int = 0
    device: str = "auto"  # torch device: auto = cuda when available, else cpu
    torch_threads: int = 0  # 0 = torch default
    # torch threads while collecting rollouts (small policy inferences next to mjbatch's
    # threads); 0 = the same as for the update
    collect_threads: int = 0
    runs_root: str = "runs"  # run store: one folder per run, named by its overrides
    force: bool = False  # re-run even when the run directory holds a completed run
    sim: SimConfig = field(default_factory=SimConfig)
    robot: RobotConfig = field(default_factory=RobotConfig)
    terrain: TerrainConfig = field(default_factory=TerrainConfig)
    difficulty: DifficultyConfig = field(default_factory=DifficultyConfig)
    task: TaskConfig = field(default_factory=TaskConfig)
    perception: PerceptionConfig = field(default_factory=PerceptionConfig)
    hardware: HardwareConfig = field(default_factory=HardwareConfig)
    actor: ActorConfig = field(default_factory=ActorConfig)
    encoder: EncoderConfig = field(default_factory=EncoderConfig)
    curriculum: CurriculumConfig = field(default_factory=CurriculumConfig)
    algo: AlgoConfig = field(default_factory=AlgoConfig)
    eval: EvalConfig = field(default_factory=EvalConfig)
    logger: LoggerConfig = field(default_factory=LoggerConfig)
    scale: ScaleConfig = field(default_factory=ScaleConfig)
    policy: PolicyConfig = field(default_factory=PolicyConfig)


def register() -> None:
    ConfigStore.instance().store(name="lca_schema", node=LcaConfig)


register()
