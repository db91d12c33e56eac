"""Typed schema of every config group; registered in Hydra's ConfigStore as `lca_schema`.

A typo in a key or a wrong type fails when Hydra composes. Value checks (ranges, sums) live
in `check()` methods that `lca.config.validate` runs right after composition.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from hydra.core.config_store import ConfigStore
from omegaconf import MISSING

TERRAIN_TYPES = ("flat", "stairs_up", "stairs_down", "uneven")


class ConfigValueError(ValueError):
    """A config value outside its allowed range; the message starts with the full key."""


def _require(ok: bool, key: str, message: str) -> None:
    if not ok:
        raise ConfigValueError(f"{key}: {message}")


def _check_range(key: str, lo_hi: list[float], low: float = 0.0) -> None:
    _require(len(lo_hi) == 2, key, f"expected [low, high], got {list(lo_hi)}")
    _require(lo_hi[0] >= low, key, f"must be >= {low}, got {list(lo_hi)}")
    _require(lo_hi[0] <= lo_hi[1], key, f"low must not exceed high, got {list(lo_hi)}")


@dataclass
class SimConfig:
    timestep: float = 0.005  # 200 Hz physics
    decimation: int = 4  # 50 Hz policy
    integrator: str = "implicitfast"
    cone: str = "pyramidal"
    iterations: int = 10  # bounded solver work per step
    ls_iterations: int = 5
    bvactive: bool = False  # MuJoCo's default (on) makes stepping ~3x slower
    num_threads: int = 0  # mjbatch worker threads; 0 = every logical CPU

    def check(self) -> None:
        _require(self.timestep > 0, "sim.timestep", f"must be > 0, got {self.timestep}")
        _require(self.decimation >= 1, "sim.decimation", f"must be >= 1, got {self.decimation}")
        allowed = ("euler", "implicit", "implicitfast", "rk4")
        _require(self.integrator in allowed, "sim.integrator", f"allowed: {allowed}")
        _require(self.cone in ("pyramidal", "elliptic"), "sim.cone", "allowed: pyramidal, elliptic")
        _require(self.iterations >= 1, "sim.iterations", f"must be >= 1, got {self.iterations}")


@dataclass
class ActuatorGroup:
    joints: list[str] = MISSING  # regexes over joint names
    rotor_inertia: list[float] = MISSING  # kg m^2 of each planetary stage, motor side first
    gear_ratio: list[float] = MISSING  # ratio of each stage (first is 1)
    motors: int = 1  # motors driving the joint through a linkage (ankles, waist roll/pitch: 2)
    effort_limit: float = MISSING  # N m


@dataclass
class RobotConfig:
    name: str = "g1"
    # PD gains from armature: kp = I w^2, kd = 2 zeta I w (w = 2 pi f); stiff yet stable at 200 Hz
    natural_frequency_hz: float = 10.0
    damping_ratio: float = 2.0
    # Explicit gains (joint name regex -> N m/rad, N m s/rad) override the armature rule for
    # the joints they match, e.g. IsaacLab's G1 gains (conf/robot/g1_isaaclab.yaml).
    stiffness: dict[str, float] = field(default_factory=dict)
    damping: dict[str, float] = field(default_factory=dict)
    actuators: dict[str, ActuatorGroup] = field(default_factory=dict)
    home: dict[str, float] = field(default_factory=dict)  # joint name regex -> angle (rad)
    home_base_height: float = 0.0  # 0: computed so the feet rest on the ground
    collision_parts: list[str] = field(default_factory=lambda: ["feet", "legs", "torso", "arms"])
    self_collision: bool = False
    foot_friction: float = 1.0
    # Sole contact spheres in the ankle-roll frame (toes, heels); the sole is at z = -0.035.
    foot_spheres: list[list[float]] = field(
        default_factory=lambda: [
            [0.13, 0.026, -0.025],
            [0.13, -0.026, -0.025],
            [-0.05, 0.02, -0.025],
            [-0.05, -0.02, -0.025],
        ]
    )
    foot_sphere_radius: float = 0.01

    def check(self) -> None:
        for name, group in self.actuators.items():
            key = f"robot.actuators.{name}"
            _require(len(group.rotor_inertia) == len(group.gear_ratio), key, "stage counts differ")
            _require(group.effort_limit > 0, f"{key}.effort_limit", "must be > 0")
        allowed = ("feet", "legs", "torso", "arms")
        for part in self.collision_parts:
            _require(
                part in allowed, "robot.collision_parts", f"unknown '{part}'; allowed: {allowed}"
            )
        _require(self.natural_frequency_hz > 0, "robot.natural_frequency_hz", "must be > 0")
        _require(self.damping_ratio > 0, "robot.damping_ratio", "must be > 0")
        for key in ("stiffness", "damping"):
            for pattern, value in getattr(self, key).items():
                _require(value >= 0, f"robot.{key}.{pattern}", f"must be >= 0, got {value}")


@dataclass
class TerrainMixture:
    flat: float = 0.0
    stairs_up: float = 0.0
    stairs_down: float = 0.0
    uneven: float = 0.0


@dataclass
class TerrainConfig:
    name: str = "mixed"
    mixture: TerrainMixture = field(default_factory=TerrainMixture)
    rows: int = 4
    cols: int = 4
    tile_size: float = 8.0  # m, square tiles
    resolution: float = 0.01  # m per heightfield sample; 1 cm keeps 0.31/0.23 m treads exact
    border: float = 1.0  # m of flat ground around the whole grid (part of the heightfield)
    # m of flat ground (boxes at height 0) beyond the heightfield on every side: a unit
    # walking 20 s in any heading never leaves the world
    apron: float = 30.0
    flat_as_plane: bool = True  # an all-flat grid is an infinite plane (cheaper contacts)
    platform: float = 1.5  # m, flat square at each tile centre where the robot spawns
    num_steps: int = 8  # steps per pyramid side (stairs_up / stairs_down)
    block_size: float = 0.4  # m, side of a block of the uneven field
    seed: int = 0

    def check(self) -> None:
        weights = [getattr(self.mixture, t) for t in TERRAIN_TYPES]
        _require(min(weights) >= 0, "terrain.mixture", f"weights must be >= 0, got {weights}")
        named = dict(zip(TERRAIN_TYPES, weights, strict=True))
        _require(
            abs(sum(weights) - 1.0) < 1e-6,
            "terrain.mixture",
            f"weights must sum to 1, got {sum(weights):.6g} ({named})",
        )
        _require(self.rows >= 1 and self.cols >= 1, "terrain.rows/cols", "must be >= 1")
        _require(self.resolution > 0, "terrain.resolution", "must be > 0")
        for key in ("tile_size", "border", "platform", "block_size"):
            value = getattr(self, key)
            _require(
                abs(value / self.resolution - round(value / self.resolution)) < 1e-6,
                f"terrain.{key}",
                f"{value} m is not a multiple of terrain.resolution={self.resolution}",
            )
        _require(self.platform < self.tile_size, "terrain.platform", "must be < tile_size")
        _require(self.apron >= 0, "terrain.apron", f"must be >= 0, got {self.apron}")
        _require(self.num_steps >= 1, "terrain.num_steps", f"must be >= 1, got {self.num_steps}")


@dataclass
class DifficultyConfig:
    name: str = "medium"
    stairs_riser: list[float] = field(default_factory=lambda: [0.14, 0.18])  # m
    stairs_tread: float = 0.31  # m
    uneven_height: list[float] = field(default_factory=lambda: [0.05, 0.20])  # m
    height_noise: float = 0.10  # m, uniform noise on the actor's heightmap (task layer)

    def check(self) -> None:
        _check_range("difficulty.stairs_riser", self.stairs_riser)
        _require(self.stairs_riser[0] > 0, "difficulty.stairs_riser", "must be > 0")
        _require(self.stairs_tread > 0, "difficulty.stairs_tread", "must be > 0")
        _check_range("difficulty.uneven_height", self.uneven_height)
        _require(self.height_noise >= 0, "difficulty.height_noise", "must be >= 0")


@dataclass
class ResetConfig:
    joint_pos_noise: float = 0.05  # rad, uniform
    joint_vel_noise: float = 0.0
    base_xy_noise: float = 0.1  # m, uniform around the tile centre
    yaw_range: float = 3.14159  # rad, uniform spawn heading


@dataclass
class RandomizationConfig:
    enabled: bool = True
    friction: list[float] = field(default_factory=lambda: [0.6, 1.25])  # scale, per reset
    added_base_mass: list[float] = field(default_factory=lambda: [-1.0, 3.0])  # kg, at start
    push_interval_s: float = 8.0  # s between pushes; 0 disables
    push_velocity: float = 0.5  # m/s, uniform planar base velocity kick


@dataclass
class ObservationConfig:
    history: int = 5  # K proprioception frames, newest first
    noise: bool = True  # actor observation noise on/off
    height_dropout: float = 0.05  # fraction of actor heightmap cells dropped (set to the mean)
    actor_grid: list[int] = field(default_factory=lambda: [11, 11])
    actor_spacing: float = 0.1  # m: 11 x 11 cells over 1.0 m x 1.0 m
    critic_grid: list[int] = field(default_factory=lambda: [16, 16])
    critic_spacing: float = 0.1  # m: 16 x 16 cells over 1.5 m x 1.5 m


@dataclass
class CommandConfig:
    lin_vel_x: list[float] = field(default_factory=lambda: [-0.6, 0.6])  # m/s
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
    only_positive: bool = False  # legged_gym's clip of the step's sum at 0 while scale < 1
    # the length- or tracking-driven scale stops at `hold` (1: no hold); from `hold_until` x
    # max_iterations it rises linearly to 1 at the deadline, so a gait found under light
    # penalties gets time to settle before the table's weights arrive
    hold: float = 1.0
    hold_until: float = 0.5
    # terms scaled (their negative contributions); empty: every term, termination included
    terms: list[str] = field(default_factory=list)

    def check(self) -> None:
        key = "task.reward_curriculum"
        _require(0 <= self.penalty_start <= 1, f"{key}.penalty_start", "must be in [0, 1]")
        _require(
            0 <= self.length_start < self.length_end <= 1,
            f"{key}.length_start/length_end",
            f"need 0 <= start < end <= 1, got {self.length_start}, {self.length_end}",
        )
        _require(0 <= self.deadline <= 1, f"{key}.deadline", "must be in [0, 1]")
        _require(0 < self.ramp <= 1, f"{key}.ramp", "must be in (0, 1]")
        _require(0 < self.hold <= 1, f"{key}.hold", "must be in (0, 1]")
        _require(
            self.hold >= 1 or 0 <= self.hold_until < self.deadline,
            f"{key}.hold_until",
            f"need 0 <= hold_until < deadline, got {self.hold_until}, {self.deadline}",
        )
        allowed = ("episode_length", "iterations", "tracking")
        _require(self.by in allowed, f"{key}.by", f"unknown '{self.by}'; allowed: {allowed}")
        from lca.task.rewards import REWARD_TERMS  # task layer owns the names

        for name in self.terms:
            _require(
                name in REWARD_TERMS,
                f"{key}.terms",
                f"unknown reward term '{name}'; allowed: {sorted(REWARD_TERMS)}",
            )


@dataclass
class CommandCurriculumConfig:
    """Early commands walk: planar commands slower than a floor are scaled up to it (their
    direction kept). The floor falls linearly from `min_speed` to 0 at `deadline` x
    max_iterations, from where commands are the configured distribution."""

    enabled: bool = False
    min_speed: float = 0.3  # m/s, the floor at the first iteration
    deadline: float = 0.6  # fraction of max_iterations where the floor reaches 0

    def check(self) -> None:
        key = "task.command_curriculum"
        _require(self.min_speed >= 0, f"{key}.min_speed", "must be >= 0")
        _require(0 <= self.deadline <= 1, f"{key}.deadline", "must be in [0, 1]")


@dataclass
class TaskConfig:
    name: str = "locomotion"
    num_envs: int = 256
    episode_length_s: float = 20.0
    action_scale: float = 0.25  # rad per unit action around the default pose
    # True: joint j's scale is action_scale * effort_limit_j / kp_j (mjlab's G1 rule), so a
    # unit action asks for the same fraction of each joint's torque
    action_scale_by_effort: bool = False
    action_clip: float = 10.0
    perception: bool = True  # False: the actor's heightmap is exactly zero
    reset: ResetConfig = field(default_factory=ResetConfig)
    randomization: RandomizationConfig = field(default_factory=RandomizationConfig)
    observations: ObservationConfig = field(default_factory=ObservationConfig)
    commands: CommandConfig = field(default_factory=CommandConfig)
    rewards: dict[str, float] = field(default_factory=dict)
    only_positive_rewards: bool = False  # clip the step's sum (but termination) at 0, always
    reward_curriculum: RewardCurriculumConfig = field(default_factory=RewardCurriculumConfig)
    command_curriculum: CommandCurriculumConfig = field(default_factory=CommandCurriculumConfig)
    reward_params: RewardParams = field(default_factory=RewardParams)
    terminations: TerminationConfig = field(default_factory=TerminationConfig)

    def check(self) -> None:
        _require(self.num_envs >= 1, "task.num_envs", f"must be >= 1, got {self.num_envs}")
        self.reward_curriculum.check()
        self.command_curriculum.check()
        _check_range("task.randomization.friction", self.randomization.friction)
        _check_range("task.randomization.added_base_mass", self.randomization.added_base_mass, -1e9)
        _require(self.observations.history >= 1, "task.observations.history", "must be >= 1")
        _require(
            0 <= self.observations.height_dropout < 1, "task.observations.height_dropout", "[0, 1)"
        )
        for key in ("lin_vel_x", "lin_vel_y", "ang_vel_z"):
            _check_range(f"task.commands.{key}", getattr(self.commands, key), -1e9)
        _require(
            0 <= self.commands.standing_fraction <= 1, "task.commands.standing_fraction", "[0, 1]"
        )
        from lca.task.rewards import REWARD_TERMS  # task layer owns the names

        for name in self.rewards:
            _require(
                name in REWARD_TERMS,
                f"task.rewards.{name}",
                f"unknown reward term; allowed: {sorted(REWARD_TERMS)}",
            )


@dataclass
class CameraConfig:
    body: str = MISSING
    pos: list[float] = MISSING  # m, in the body frame
    pitch_deg: float = 60.0  # optical axis below horizontal
    yaw_deg: float = 0.0  # 180 looks backwards
    fov_h_deg: float = 87.0  # Intel RealSense D435 depth field of view
    fov_v_deg: float = 58.0
    rays_h: int = 24  # ray grid subsampling the D435's 848 x 480 (CPU cost)
    rays_w: int = 36
    min_range: float = 0.1
    max_range: float = 3.0
    noise_k: float = 0.004  # depth noise sigma = k d^2 (stereo error grows with d^2)
    invalid_fraction: float = 0.02  # pixels with no depth


@dataclass
class PerceptionConfig:
    name: str = "privileged"
    source: str = "privileged"  # privileged: exact grid + noise; deployment: cameras + filter
    rate_hz: float = 30.0  # camera rate; the 50 Hz policy reads the latest map
    outlier_gamma: float = 2.0  # cells with |g - mu| >= gamma sigma are set to mu
    quantum: float = 0.05  # m, map quantisation (paper)
    cameras: list[CameraConfig] = field(default_factory=list)

    def check(self) -> None:
        allowed = ("privileged", "deployment")
        _require(self.source in allowed, "perception.source", f"allowed: {allowed}")
        _require(
            self.source == "privileged" or len(self.cameras) > 0,
            "perception.cameras",
            "the deployment pipeline needs at least one camera",
        )


HARDWARE_TASKS = ("stair_ascent", "stair_descent", "hinged_ledge", "soft_ledge")


@dataclass
class StairTaskConfig:
    steps: int = 3
    riser: float = 0.18  # m
    landing: float = 0.20  # m, tread depth
    skew_deg: float = 25.0  # stair edges rotated in the horizontal plane


@dataclass
class HingedPlankConfig:
    length: float = 1.2  # m
    width: float = 0.6
    thickness: float = 0.04
    pivot_height: float = 0.10  # m, plank centre above the ground when level
    tip_deg: float = 12.0  # hinge range: the plank tips this far either way
    mass: float = 6.0  # kg
    damping: float = 2.0  # N m s / rad
    gap: float = 0.05  # m between the ledge wall and the plank's near end


@dataclass
class SoftMatConfig:
    length: float = 1.2  # m
    width: float = 1.0
    thickness: float = 0.10
    solref: list[float] = field(default_factory=lambda: [0.08, 0.7])  # soft: slow, underdamped
    solimp: list[float] = field(default_factory=lambda: [0.3, 0.9, 0.06, 0.5, 2.0])


@dataclass
class HardwareConfig:
    name: str = "default"
    tasks: list[str] = field(default_factory=lambda: list(HARDWARE_TASKS))
    trials: int = 5
    command_x: float = 0.3  # m/s forward from a standing start (paper)
    time_limit_s: float = 20.0
    approach: float = 1.0  # m of flat ground (or platform) before the feature
    goal_past: float = 0.6  # m past the feature's end that counts as completed
    ledge_drop: float = 0.36  # m (paper)
    resolution: float = 0.01  # m, heightfield of the static geometry
    stairs: StairTaskConfig = field(default_factory=StairTaskConfig)
    plank: HingedPlankConfig = field(default_factory=HingedPlankConfig)
    mat: SoftMatConfig = field(default_factory=SoftMatConfig)

    def check(self) -> None:
        for task in self.tasks:
            _require(
                task in HARDWARE_TASKS,
                "hardware.tasks",
                f"unknown '{task}'; allowed: {HARDWARE_TASKS}",
            )
        _require(self.trials >= 1, "hardware.trials", "must be >= 1")


ACTOR_KINDS = ("mlp", "lstm")
ENCODER_KINDS = ("cnn", "mlp")


@dataclass
class ActorConfig:
    name: str = "mlp"
    kind: str = "mlp"  # mlp | lstm
    hidden_dims: list[int] = field(default_factory=lambda: [512, 256, 128])
    activation: str = "elu"
    rnn_hidden_dim: int = 256  # LSTM width before the MLP head (lstm only)
    init_noise_std: float = 1.0
    # joint group (legs, waist, arms) or joint name regex -> initial action std of its joints
    # (first match wins); e.g. a quiet upper body while the legs explore
    init_noise_std_joints: dict[str, float] = field(default_factory=dict)
    # > 0: the action std is capped by a ceiling falling linearly from init_noise_std to this
    # value at `noise_deadline` x max_iterations (and staying there): explore early, act
    # precisely once the penalties are the paper's. 0: rsl-rl's free, learned std.
    final_noise_std: float = 0.0
    noise_deadline: float = 0.6
    noise_start: float = 0.0  # iterations: the ceiling stays at init_noise_std until here
    # what lowers the ceiling: the iteration (to noise_deadline) or the reward curriculum's
    # progress (the ceiling reaches final_noise_std as the penalties reach the paper's)
    noise_by: str = "iterations"

    def check(self) -> None:
        _require(
            self.kind in ACTOR_KINDS, "actor.kind", f"unknown '{self.kind}'; allowed: {ACTOR_KINDS}"
        )
        _require(self.init_noise_std > 0, "actor.init_noise_std", "must be > 0")
        _require(
            0 <= self.final_noise_std <= self.init_noise_std,
            "actor.final_noise_std",
            f"must be in [0, init_noise_std={self.init_noise_std}], got {self.final_noise_std}",
        )
        _require(0 <= self.noise_deadline <= 1, "actor.noise_deadline", "must be in [0, 1]")
        _require(
            0 <= self.noise_start < max(self.noise_deadline, 1e-9) or self.noise_start == 0,
            "actor.noise_start",
            f"need 0 <= noise_start < noise_deadline, got {self.noise_start}",
        )
        allowed = ("iterations", "penalties")
        _require(self.noise_by in allowed, "actor.noise_by", f"allowed: {allowed}")


@dataclass
class EncoderConfig:
    name: str = "cnn"
    kind: str = "cnn"  # cnn | mlp
    hidden_dims: list[int] = field(default_factory=lambda: [256, 256])
    latent_dim: int = 32  # z_H
    conv_channels: list[int] = field(default_factory=lambda: [8, 16])  # cnn only
    kernel_size: int = 3
    stride: int = 1
    pool: int = 0  # max-pool after each convolution (cnn only); 0: none (the paper's CNN)

    def check(self) -> None:
        _require(
            self.kind in ENCODER_KINDS,
            "encoder.kind",
            f"unknown '{self.kind}'; allowed: {ENCODER_KINDS}",
        )
        _require(
            self.pool in (0, 2, 3), "encoder.pool", f"allowed: 0 (none), 2, 3; got {self.pool}"
        )


@dataclass
class CurriculumConfig:
    name: str = "two"
    perception_from: float = 0.5  # fraction of iterations after which the actor sees its map

    def check(self) -> None:
        _require(
            0.0 <= self.perception_from <= 1.0, "curriculum.perception_from", "must be in [0, 1]"
        )


@dataclass
class AlgoConfig:
    name: str = "ppo"
    num_steps_per_env: int = 24
    num_learning_epochs: int = 5
    num_mini_batches: int = 4
    clip_param: float = 0.2
    gamma: float = 0.99
    lam: float = 0.95
    value_loss_coef: float = 1.0
    entropy_coef: float = 0.005
    learning_rate: float = 1.0e-3
    max_grad_norm: float = 1.0
    schedule: str = "adaptive"
    desired_kl: float = 0.01
    obs_normalization: bool = True
    symmetry: bool = False  # rsl-rl symmetry_cfg: every mini-batch also holds its mirror image
    mirror_loss_coeff: float = 0.0  # > 0 adds rsl-rl's mirror loss (MLP actors only)

    def check(self) -> None:
        def positive(key: str) -> None:
            value = getattr(self, key)
            _require(value > 0, f"algo.{key}", f"must be > 0, got {value}")

        def at_least_one(key: str) -> None:
            value = getattr(self, key)
            _require(value >= 1, f"algo.{key}", f"must be >= 1, got {value}")

        for key in ("learning_rate", "clip_param", "max_grad_norm", "desired_kl"):
            positive(key)
        for key in ("num_steps_per_env", "num_learning_epochs", "num_mini_batches"):
            at_least_one(key)
        for key in ("entropy_coef", "value_loss_coef", "mirror_loss_coeff"):
            value = getattr(self, key)
            _require(value >= 0, f"algo.{key}", f"must be >= 0, got {value}")
        _require(0 < self.gamma <= 1, "algo.gamma", f"must be in (0, 1], got {self.gamma}")
        _require(0 <= self.lam <= 1, "algo.lam", f"must be in [0, 1], got {self.lam}")
        allowed = ("adaptive", "fixed")
        _require(
            self.schedule in allowed,
            "algo.schedule",
            f"unknown '{self.schedule}'; allowed: {allowed}",
        )


EVAL_TERRAINS = ("stairs", "uneven", "flat", "stairs_up", "stairs_down", "mixed")
DIFFICULTIES = ("medium", "hard")


@dataclass
class EvalCell:
    terrain: str = MISSING  # stairs (= half up, half down) | uneven | flat | stairs_up | ...
    difficulty: str = MISSING  # medium | hard


@dataclass
class EvalConfig:
    name: str = "default"
    units: int = 32  # simulated robots per cell (paper: 500)
    episodes: int = 2  # episodes per unit (paper: 3)
    steps: int = 500  # policy steps per episode (paper: 1000)
    cells: list[EvalCell] = field(
        default_factory=lambda: [
            EvalCell(t, d) for t in ("stairs", "uneven") for d in ("medium", "hard")
        ]
    )
    command_x: list[float] = field(default_factory=lambda: [0.3, 0.6])  # m/s forward
    seed: int = 12345
    bootstrap_resamples: int = 2000
    confidence: float = 0.95
    videos: bool = True  # after evaluation: a clip per cell and terrain previews (needs GL)
    video_seconds: float = 4.0  # length of each cell's clip

    def check(self) -> None:
        for key in ("units", "episodes", "steps"):
            _require(getattr(self, key) >= 1, f"eval.{key}", "must be >= 1")
        _require(
            self.video_seconds > 0, "eval.video_seconds", f"must be > 0, got {self.video_seconds}"
        )
        for i, cell in enumerate(self.cells):
            _require(
                cell.terrain in EVAL_TERRAINS,
                f"eval.cells[{i}].terrain",
                f"unknown '{cell.terrain}'; allowed: {EVAL_TERRAINS}",
            )
            _require(
                cell.difficulty in DIFFICULTIES,
                f"eval.cells[{i}].difficulty",
                f"unknown '{cell.difficulty}'; allowed: {DIFFICULTIES}",
            )
        _check_range("eval.command_x", self.command_x, -1e9)


@dataclass
class LoggerConfig:
    name: str = "tensorboard"  # tensorboard | wandb | none
    wandb_project: str = "lca"
    wandb_mode: str = "offline"  # used unless WANDB_MODE is set in the environment

    def check(self) -> None:
        allowed = ("tensorboard", "wandb", "none")
        _require(self.name in allowed, "logger.name", f"unknown '{self.name}'; allowed: {allowed}")


@dataclass
class ScaleConfig:
    name: str = "cpu"
    max_iterations: int = 100
    log_interval: int = 5  # iterations between progress lines
    checkpoint_interval: int = 25  # iterations between resumable checkpoints

    def check(self) -> None:
        for key in ("max_iterations", "log_interval", "checkpoint_interval"):
            value = getattr(self, key)
            _require(value >= 1, f"scale.{key}", f"must be >= 1, got {value}")


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


def register() -> None:
    ConfigStore.instance().store(name="lca_schema", node=LcaConfig)


register()
