"""Config group of the task stage: the locomotion MDP (resets, randomisation, observations,
commands, rewards and their curricula, terminations)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from omegaconf import MISSING

from lca.config.errors import check_range, require
from lca.config.registry import OBS_TERMS, REWARD_TERMS
from lca.config.schema import group
from lca.sim.config import CameraConfig, ResetConfig


@dataclass
class RandomizationConfig:
    enabled: bool = True
    friction: list[float] = field(default_factory=lambda: [0.6, 1.25])  # scale, per reset
    added_base_mass: list[float] = field(default_factory=lambda: [-1.0, 3.0])  # kg, at start
    push_interval_s: float = 8.0  # s between pushes; 0 disables
    push_velocity: float = 0.5  # m/s, uniform planar base velocity kick


@dataclass
class ObsTermConfig:
    name: str = MISSING  # a registered observation term (lca.task.observations)
    scale: Any = 1.0  # a number, or one per dimension
    noise: float = 0.0  # half-width of uniform noise on the raw value (actor only)
    clip: float | None = None  # |scaled value| bound; None: unbounded


@dataclass
class ObservationConfig:
    history: int = 5  # K: the paper leaves it open; 5 frames (0.1 s), newest first
    # the terms of each history frame, in order, and the current terms after the history:
    # declared in conf/task/<task>.yaml only
    proprioception: list[ObsTermConfig] = MISSING
    current: list[ObsTermConfig] = MISSING
    noise: bool = True  # actor observation noise on/off
    # the sparse map: this share of the actor's cells is dropped (set to the mean) per step
    height_dropout: float = 0.05
    actor_grid: list[int] = field(default_factory=lambda: [11, 11])  # paper
    actor_spacing: float = 0.1  # m: 11 x 11 cells over 1.0 m x 1.0 m (paper)
    critic_grid: list[int] = field(default_factory=lambda: [16, 16])  # paper
    critic_spacing: float = 0.1  # m: 16 x 16 cells over 1.5 m x 1.5 m (paper)


@dataclass
class CommandConfig:
    lin_vel_x: list[float] = field(default_factory=lambda: [-0.6, 0.6])  # m/s; paper: up to 0.6
    lin_vel_y: list[float] = field(default_factory=lambda: [-0.3, 0.3])  # m/s
    ang_vel_z: list[float] = field(default_factory=lambda: [-0.5, 0.5])  # rad/s
    standing_fraction: float = 0.1  # share of commands that are exactly zero
    resample_time_s: float = 10.0
    standing_epsilon: float = 5e-3  # ||u|| below this is a standing command (paper)


@dataclass
class RewardParams:
    tracking_sigma: float = 0.25  # exp(-err^2 / 0.25) (paper)
    gait_period: float = 0.8  # s (paper)
    stance_fraction: float = 0.55  # tau (paper)
    contact_threshold: float = 1.0  # N (paper F*)
    strike_threshold: float = 100.0  # N of lateral foot force that counts as a strike (paper)
    base_height_target: float = 0.77  # m above the ground (paper)
    swing_height: float = 0.08  # m, nominal swing clearance of the sole
    stand_height: float = 0.0  # m, target when standing: the sole site is on the sole
    clearance_scale: float = 0.08  # m, h_scale normalising the clearance error
    clearance_gate: float = 10.0  # kappa in tanh(kappa * |v_xy|)
    flat_feet_k: float = 25.0  # k_theta (paper)
    soft_limit_factor: float = 0.95  # joint range share inside which dof_pos_limits is zero


@dataclass
class TerminationConfig:
    min_base_height: float = 0.35  # m above the ground
    max_tilt: float = 1.0  # rad between base z-axis and world z
    max_joint_vel: float = 1000.0  # rad/s; above this the state counts as non-finite


@dataclass
class RewardCurriculumConfig:
    """Penalties (every negative reward contribution, the termination penalty included)
    scaled from `penalty_start` up to the paper's weights as the mean episode length grows.
    The scale never decreases and is exactly 1 from `deadline` x max_iterations on, so
    training always ends on the paper's objective."""

    enabled: bool = False
    penalty_start: float = 0.1  # fraction of the paper's penalty weights at the start
    # what raises the scale: the mean episode length (length_start -> length_end); the
    # iteration (linearly from 0 to the deadline); or tracking: a step per iteration while
    # episodes are long enough (length_start) and the robot follows its commands (gate)
    by: str = "episode_length"
    gate: float = 0.5  # tracking: 1 - |u - v| / |u| over moving commands needed to step up
    ramp: float = 0.25  # tracking: fraction of max_iterations a full, never-gated ramp takes
    length_start: float = 0.2  # ramp starts at this mean episode length (fraction of the max)
    length_end: float = 0.8  # ... and reaches the paper's weights at this one
    deadline: float = 0.75  # fraction of max_iterations from which the weights are the paper's
    # fraction of max_iterations at which the ramp, the clip, the sigma and every boost window
    # open by then end at once (1: no cut); a window that opens at or after it still applies
    cut: float = 1.0
    only_positive: bool = False  # legged_gym's clip of the step's sum at 0 while scale < 1
    # the length- or tracking-driven scale stops at `hold` (1: no hold); from `hold_until` x
    # max_iterations it rises linearly to 1 at the deadline, so a gait found under light
    # penalties gets time to settle before the table's weights arrive
    hold: float = 1.0
    hold_until: float = 0.5
    # terms scaled (their negative contributions); empty: every term, termination included
    terms: list[str] = field(default_factory=list)
    # term -> factor on its weight at the start, falling linearly to 1 as the penalties reach
    # the table's (e.g. {phase_contact: 4}: step with the gait clock before anything else)
    boost: dict[str, float] = field(default_factory=dict)
    # [start, end] fractions of max_iterations: the boosts apply from `start` and fall linearly
    # to 1 at `end` instead (e.g. [0.8, 0.9]: speed up a gait formed under the table's weights).
    # []: from the first iteration until the penalties are the table's
    boost_window: list[float] = field(default_factory=list)
    # term -> its own [start, end] window instead of boost_window (e.g. {termination_penalty:
    # [0.64, 0.9]} with cut 0.64: a fall costs more while the table's costs first arrive)
    boost_windows: dict[str, list[float]] = field(default_factory=dict)
    # factor on the tracking kernels' sigma, on the boosts' schedule (back to 1 with them):
    # 0.2 makes standing still at a 0.45 m/s command earn 2 % of the velocity kernel instead
    # of the paper's 44 %, so a stall at a riser no longer pays nearly as well as a walk
    sigma_scale: float = 1.0
    # terms added after the clip, like the termination penalty: their gradient reaches the
    # policy even while the clipped sum is negative (e.g. the posture terms, so that the
    # posture forms with the gait instead of after it)
    unclipped: list[str] = field(default_factory=list)

    def check(self) -> None:
        key = "task.reward_curriculum"
        require(0 <= self.penalty_start <= 1, f"{key}.penalty_start", "must be in [0, 1]")
        require(
            0 <= self.length_start < self.length_end <= 1,
            f"{key}.length_start/length_end",
            f"need 0 <= start < end <= 1, got {self.length_start}, {self.length_end}",
        )
        require(0 <= self.deadline <= 1, f"{key}.deadline", "must be in [0, 1]")
        require(0 < self.cut <= 1, f"{key}.cut", f"must be in (0, 1], got {self.cut}")
        require(0 < self.ramp <= 1, f"{key}.ramp", "must be in (0, 1]")
        require(0 < self.hold <= 1, f"{key}.hold", "must be in (0, 1]")
        require(
            self.hold >= 1 or 0 <= self.hold_until < self.deadline,
            f"{key}.hold_until",
            f"need 0 <= hold_until < deadline, got {self.hold_until}, {self.deadline}",
        )
        allowed = ("episode_length", "iterations", "tracking")
        require(self.by in allowed, f"{key}.by", f"unknown '{self.by}'; allowed: {allowed}")
        for part in ("terms", "unclipped"):
            for name in getattr(self, part):
                REWARD_TERMS.check(name, f"{key}.{part}")
        windows = {"boost_window": self.boost_window}
        windows |= {f"boost_windows.{k}": w for k, w in self.boost_windows.items()}
        for name, window in windows.items():
            require(
                not window or (len(window) == 2 and 0 <= window[0] < window[1] < 1),
                f"{key}.{name}",
                f"need [start, end] with 0 <= start < end < 1 (the run ends on the table's "
                f"weights), got {list(window)}",
            )
        for name in self.boost_windows:
            require(name in self.boost, f"{key}.boost_windows.{name}", "is not in boost")
        require(self.sigma_scale > 0, f"{key}.sigma_scale", f"must be > 0, got {self.sigma_scale}")
        for name, factor in self.boost.items():
            REWARD_TERMS.check(name, f"{key}.boost.{name}")
            require(factor > 0, f"{key}.boost.{name}", f"must be > 0, got {factor}")


@dataclass
class CommandRangesConfig:
    """Command ranges the curriculum starts from; a field left None is the configured one."""

    lin_vel_x: list[float] | None = None  # m/s, [low, high]
    lin_vel_y: list[float] | None = None  # m/s
    ang_vel_z: list[float] | None = None  # rad/s
    standing_fraction: float | None = None


@dataclass
class CommandCurriculumConfig:
    """Early commands walk: planar commands slower than a floor are scaled up to it (their
    direction kept), and the command ranges widen from `widen_from` to the configured ones.
    Both end linearly at `deadline` x max_iterations, from where commands are the configured
    distribution."""

    enabled: bool = False
    min_speed: float = 0.3  # m/s, the floor at the first iteration
    deadline: float = 0.6  # fraction of max_iterations where the floor reaches 0
    # the ranges at the first iteration (e.g. lin_vel_x: [0.3, 0.6], lin_vel_y: [0, 0]: forward
    # only, so that a gait that walks forward is also one that follows its commands)
    widen_from: CommandRangesConfig = field(default_factory=CommandRangesConfig)

    def check(self) -> None:
        key = "task.command_curriculum"
        require(self.min_speed >= 0, f"{key}.min_speed", "must be >= 0")
        require(0 <= self.deadline <= 1, f"{key}.deadline", "must be in [0, 1]")
        for name in ("lin_vel_x", "lin_vel_y", "ang_vel_z"):
            bounds = getattr(self.widen_from, name)
            if bounds is not None:
                require(
                    len(bounds) == 2 and bounds[0] <= bounds[1],
                    f"{key}.widen_from.{name}",
                    f"need [low, high] with low <= high, got {list(bounds)}",
                )
        fraction = self.widen_from.standing_fraction
        require(
            fraction is None or 0 <= fraction <= 1,
            f"{key}.widen_from.standing_fraction",
            "must be in [0, 1]",
        )


@group("task")
@dataclass
class TaskConfig:
    name: str = "locomotion"
    num_envs: int = 256
    episode_length_s: float = 20.0  # 1000 policy steps at 50 Hz, the paper's episode
    # joint target = default + action_scale * action, rad (legged-gym practice)
    action_scale: float = 0.25
    # True: joint j's scale is action_scale * effort_limit_j / kp_j (mjlab's G1 rule), so a
    # unit action asks for the same fraction of each joint's torque
    action_scale_by_effort: bool = False
    action_clip: float = 10.0
    perception: bool = True  # False: the actor's heightmap is exactly zero
    reset: ResetConfig = field(default_factory=ResetConfig)
    randomization: RandomizationConfig = field(default_factory=RandomizationConfig)
    observations: ObservationConfig = field(default_factory=ObservationConfig)
    commands: CommandConfig = field(default_factory=CommandConfig)
    # term name -> weight, or {weight: w, params: {...}} (mjlab's form: the term is called as
    # f(ctx, **params)); names are the registered reward terms (lca.task.rewards). Declared
    # in conf/task/<task>.yaml only: the paper's table "Nominal reward terms"
    rewards: dict[str, Any] = MISSING
    # legged_gym's clip of the step's sum (but termination) at 0, for the whole run. Off: the
    # paper optimises its table unclipped; the reward curriculum can clip as an early stage
    only_positive_rewards: bool = False
    reward_curriculum: RewardCurriculumConfig = field(default_factory=RewardCurriculumConfig)
    command_curriculum: CommandCurriculumConfig = field(default_factory=CommandCurriculumConfig)
    reward_params: RewardParams = field(default_factory=RewardParams)
    terminations: TerminationConfig = field(default_factory=TerminationConfig)

    def check(self) -> None:
        require(self.num_envs >= 1, "task.num_envs", f"must be >= 1, got {self.num_envs}")
        self.reward_curriculum.check()
        self.command_curriculum.check()
        check_range("task.randomization.friction", self.randomization.friction)
        check_range("task.randomization.added_base_mass", self.randomization.added_base_mass, -1e9)
        require(self.observations.history >= 1, "task.observations.history", "must be >= 1")
        for part in ("proprioception", "current"):
            for i, term in enumerate(getattr(self.observations, part)):
                key = f"task.observations.{part}[{i}]"
                OBS_TERMS.check(term.name, f"{key}.name")
                require(term.noise >= 0, f"{key}.noise", f"must be >= 0, got {term.noise}")
                require(term.clip is None or term.clip > 0, f"{key}.clip", "must be > 0 or null")
        require(
            0 <= self.observations.height_dropout < 1, "task.observations.height_dropout", "[0, 1)"
        )
        for key in ("lin_vel_x", "lin_vel_y", "ang_vel_z"):
            check_range(f"task.commands.{key}", getattr(self.commands, key), -1e9)
        require(
            0 <= self.commands.standing_fraction <= 1, "task.commands.standing_fraction", "[0, 1]"
        )
        for name, entry in self.rewards.items():
            key = f"task.rewards.{name}"
            REWARD_TERMS.check(name, key)
            if isinstance(entry, dict):
                extra = sorted(set(entry) - {"weight", "params"})
                require(not extra, key, f"unknown field(s) {extra}; allowed: weight, params")
                require("weight" in entry, key, "needs a weight")
                require(isinstance(entry.get("params", {}), dict), f"{key}.params", "a mapping")
                entry = entry["weight"]
            require(
                isinstance(entry, int | float) and not isinstance(entry, bool),
                key,
                f"the weight must be a number, got {entry!r}",
            )


@group("perception")
@dataclass
class PerceptionConfig:
    """privileged (the training default): the exact terrain grid with the difficulty's noise
    and dropout; deployment: depth cameras and the paper's filter."""

    name: str = "privileged"
    source: str = "privileged"  # privileged: exact grid + noise; deployment: cameras + filter
    rate_hz: float = 30.0  # camera rate; the 50 Hz policy reads the latest map
    outlier_gamma: float = 2.0  # cells with |g - mu| >= gamma sigma are set to mu
    quantum: float = 0.05  # m, map quantisation (paper)
    cameras: list[CameraConfig] = field(default_factory=list)

    def check(self) -> None:
        allowed = ("privileged", "deployment")
        require(self.source in allowed, "perception.source", f"allowed: {allowed}")
        require(
            self.source == "privileged" or len(self.cameras) > 0,
            "perception.cameras",
            "the deployment pipeline needs at least one camera",
        )
