"""Config groups of the simulation stage: physics, robot, terrain, difficulty."""

from __future__ import annotations

import importlib.util
from dataclasses import dataclass, field

from omegaconf import MISSING

from lca.config.errors import check_range, require
from lca.config.registry import TILES
from lca.config.schema import group

AFTER_LEVELS = ("top_row", "full_grid")  # terrain.after_levels


@group("sim")
@dataclass
class SimConfig:
    timestep: float = 0.005  # 200 Hz physics
    decimation: int = 4  # 50 Hz policy
    integrator: str = "implicitfast"  # implicit PD damping, cheaper than implicit
    cone: str = "pyramidal"  # cheaper than elliptic at 10 iterations
    iterations: int = 10  # bounded solver work per physics step
    ls_iterations: int = 5
    bvactive: bool = False  # MuJoCo's default (on) makes stepping ~3x slower
    num_threads: int = 0  # mjbatch worker threads; 0 = every logical CPU
    # mjbatch: MuJoCo C on CPU threads; warp: MuJoCo-Warp (pip install -e ".[gpu]")
    backend: str = "mjbatch"
    warp_device: str = "auto"  # auto: cuda when warp sees a GPU, else warp's CPU device
    nconmax: int = 0  # warp's contacts per world; 0: sized from the scene's colliding geoms
    njmax: int = 0  # warp's constraint rows per world; 0: sized from the contacts and limits

    def check(self) -> None:
        require(self.timestep > 0, "sim.timestep", f"must be > 0, got {self.timestep}")
        require(self.decimation >= 1, "sim.decimation", f"must be >= 1, got {self.decimation}")
        allowed = ("euler", "implicit", "implicitfast", "rk4")
        require(self.integrator in allowed, "sim.integrator", f"allowed: {allowed}")
        require(self.cone in ("pyramidal", "elliptic"), "sim.cone", "allowed: pyramidal, elliptic")
        require(self.iterations >= 1, "sim.iterations", f"must be >= 1, got {self.iterations}")
        allowed = ("mjbatch", "warp")
        require(
            self.backend in allowed, "sim.backend", f"unknown '{self.backend}'; allowed: {allowed}"
        )
        require(
            self.backend != "warp" or importlib.util.find_spec("mujoco_warp") is not None,
            "sim.backend",
            "warp needs MuJoCo-Warp, which is not installed: pip install -e '.[gpu]'",
        )
        require(self.nconmax >= 0 and self.njmax >= 0, "sim.nconmax/njmax", "must be >= 0")


@dataclass
class ActuatorGroup:
    joints: list[str] = MISSING  # regexes over joint names
    rotor_inertia: list[float] = MISSING  # kg m^2 of each planetary stage, motor side first
    gear_ratio: list[float] = MISSING  # ratio of each stage (first is 1)
    motors: int = 1  # motors driving the joint through a linkage (ankles, waist roll/pitch: 2)
    effort_limit: float = MISSING  # N m


@group("robot")
@dataclass
class RobotConfig:
    name: str = "g1"
    # PD gains from armature: kp = I w^2, kd = 2 zeta I w (w = 2 pi f); stiff yet stable at 200 Hz
    natural_frequency_hz: float = 10.0
    damping_ratio: float = 2.0  # overdamped, as in mjlab's G1
    # Explicit gains (joint name regex -> N m/rad, N m s/rad) override the armature rule for
    # the joints they match, e.g. IsaacLab's G1 gains (conf/robot/g1_isaaclab.yaml).
    stiffness: dict[str, float] = field(default_factory=dict)
    damping: dict[str, float] = field(default_factory=dict)
    actuators: dict[str, ActuatorGroup] = field(default_factory=dict)
    home: dict[str, float] = field(default_factory=dict)  # joint name regex -> angle (rad)
    home_base_height: float = 0.0  # 0: computed so the feet rest on the ground
    # primitives that touch terrain and task objects (not each other)
    collision_parts: list[str] = field(default_factory=lambda: ["feet", "legs", "torso", "arms"])
    self_collision: bool = False  # robot-robot contacts off for speed
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
    foot_sphere_radius: float = 0.01  # sphere bottoms sit on the sole plane z = -0.035

    def check(self) -> None:
        for name, actuator in self.actuators.items():
            key = f"robot.actuators.{name}"
            require(
                len(actuator.rotor_inertia) == len(actuator.gear_ratio), key, "stage counts differ"
            )
            require(actuator.effort_limit > 0, f"{key}.effort_limit", "must be > 0")
        allowed = ("feet", "legs", "torso", "arms")
        for part in self.collision_parts:
            require(
                part in allowed, "robot.collision_parts", f"unknown '{part}'; allowed: {allowed}"
            )
        require(self.natural_frequency_hz > 0, "robot.natural_frequency_hz", "must be > 0")
        require(self.damping_ratio > 0, "robot.damping_ratio", "must be > 0")
        for key in ("stiffness", "damping"):
            for pattern, value in getattr(self, key).items():
                require(value >= 0, f"robot.{key}.{pattern}", f"must be >= 0, got {value}")


@group("terrain")
@dataclass
class TerrainConfig:
    name: str = "mixed"
    mixture: dict[str, float] = field(default_factory=dict)  # tile name -> weight (sum 1)
    # 2 x 2 tiles: one of each kind of the mixture. Every box of the terrain costs every env
    # physics time, and most boxes are uneven blocks (400 a tile): the mixed terrain trains
    # at 0.85-0.89x the plane's rate on this grid, 0.75x on 4 x 4 (reports/benchmarks.md).
    # More tiles give more riser draws; evaluation cells use eval.grid's tiles.
    rows: int = 2
    cols: int = 2
    tile_size: float = 8.0  # m, square tiles
    resolution: float = 0.01  # m per heightfield sample; 1 cm keeps 0.31/0.23 m treads exact
    border: float = 1.0  # m of flat ground around the whole grid (part of the heightfield)
    # m of flat ground (boxes at height 0) beyond the heightfield on every side: a unit
    # walking 20 s in any heading never leaves the world
    apron: float = 30.0
    flat_as_plane: bool = True  # an all-flat grid is an infinite plane (cheaper contacts)
    # what the physics collides with. boxes: each tile's treads, platforms and blocks as box
    # geoms, risers vertical (reports/benchmarks.md: 2x cheaper than the heightfield);
    # heightfield: the 1 cm samples, risers a 1 cm ramp. The same drawn terrain either way.
    representation: str = "boxes"
    # IsaacLab's terrain_levels_vel curriculum (not in the paper, which names no terrain
    # curriculum): rows are difficulty levels, easiest first, one tile type per column;
    # training envs move up a row after walking half a tile, down after covering less than
    # half their commanded distance, and past the top row restart on a random one
    levels: bool = False
    max_init_level: int = 0  # envs start on rows 0..this (IsaacLab: 5 of 10)
    # fraction of the difficulty's riser and block heights on row 0, rising evenly to 1 on
    # the top row (None: 1 / rows, rows of equal steps); 0 makes row 0 flat ground
    levels_from: float | None = None
    # fraction of the run from which the curriculum is over: every env resets onto the top
    # row, the configured difficulty itself (1.0: never, IsaacLab's way)
    levels_end: float = 1.0
    # what follows the curriculum: top_row (every env on the levelled grid's top row, one
    # tile of each kind) or full_grid (the terrain rebuilt once as the grid without levels:
    # every tile at the difficulty, kinds by the mixture, as evaluation draws it)
    after_levels: str = "top_row"
    # practice (not in the paper): until practice_end (a fraction of the run) the envs respawn
    # on the tile kinds in these shares ({stairs_up: 0.5, ...}) instead of evenly over the
    # grid; the terrain is unchanged, and from practice_end on the spread is even again
    # (1: the run ends while it practises).
    # Set it with a leading +: `+terrain.practice={stairs_up: 0.5, flat: 0.5}`
    practice: dict[str, float] = field(default_factory=dict)
    practice_start: float = 0.0  # from here (e.g. after a levelled start) until practice_end
    practice_end: float = 0.0
    platform: float = 1.5  # m, flat square at each tile centre where the robot spawns
    num_steps: int = 8  # steps per pyramid side (stairs_up / stairs_down)
    block_size: float = 0.4  # m, side of a block of the uneven field
    seed: int = 0

    def check(self) -> None:
        for name in self.mixture:
            TILES.check(name, f"terrain.mixture.{name}")
        named = dict(self.mixture)
        weights = list(named.values()) or [0.0]
        require(min(weights) >= 0, "terrain.mixture", f"weights must be >= 0, got {named}")
        require(
            abs(sum(weights) - 1.0) < 1e-6,
            "terrain.mixture",
            f"weights must sum to 1, got {sum(weights):.6g} ({named})",
        )
        allowed = ("boxes", "heightfield")
        require(
            self.representation in allowed,
            "terrain.representation",
            f"unknown '{self.representation}'; allowed: {allowed}",
        )
        require(self.rows >= 1 and self.cols >= 1, "terrain.rows/cols", "must be >= 1")
        require(self.resolution > 0, "terrain.resolution", "must be > 0")
        for key in ("tile_size", "border", "platform", "block_size"):
            value = getattr(self, key)
            require(
                abs(value / self.resolution - round(value / self.resolution)) < 1e-6,
                f"terrain.{key}",
                f"{value} m is not a multiple of terrain.resolution={self.resolution}",
            )
        require(self.platform < self.tile_size, "terrain.platform", "must be < tile_size")
        self._check_practice()
        require(self.apron >= 0, "terrain.apron", f"must be >= 0, got {self.apron}")
        require(self.num_steps >= 1, "terrain.num_steps", f"must be >= 1, got {self.num_steps}")
        require(
            0 <= self.max_init_level < self.rows,
            "terrain.max_init_level",
            f"must be in [0, rows - 1 = {self.rows - 1}], got {self.max_init_level}",
        )
        require(
            self.levels_from is None or 0 <= self.levels_from <= 1,
            "terrain.levels_from",
            f"must be a fraction of the difficulty in [0, 1] or null, got {self.levels_from}",
        )
        require(
            0 <= self.levels_end <= 1,
            "terrain.levels_end",
            f"must be a fraction of the run in [0, 1], got {self.levels_end}",
        )
        require(
            self.after_levels in AFTER_LEVELS,
            "terrain.after_levels",
            f"unknown '{self.after_levels}'; allowed: {AFTER_LEVELS}",
        )

    def _check_practice(self) -> None:
        share = dict(self.practice)
        if not share and self.practice_end == 0:
            return
        kinds = sorted(k for k, w in self.mixture.items() if w > 0)
        for name in share:
            require(
                name in kinds,
                f"terrain.practice.{name}",
                f"not a tile kind of terrain.mixture; allowed: {kinds}",
            )
        weights = list(share.values()) or [0.0]
        require(
            min(weights) >= 0 and abs(sum(weights) - 1.0) < 1e-6,
            "terrain.practice",
            f"shares must be >= 0 and sum to 1, got {share}",
        )
        require(
            0 < self.practice_end <= 1,
            "terrain.practice_end",
            f"must be in (0, 1] with terrain.practice set, got {self.practice_end}",
        )
        require(
            0 <= self.practice_start < self.practice_end,
            "terrain.practice_start",
            f"must be in [0, practice_end = {self.practice_end}), got {self.practice_start}",
        )


@group("difficulty")
@dataclass
class DifficultyConfig:
    """The paper's table "Environment parameters" (m); medium is in-distribution."""

    name: str = "medium"
    stairs_riser: list[float] = field(default_factory=lambda: [0.14, 0.18])  # m
    stairs_tread: float = 0.31  # m
    uneven_height: list[float] = field(default_factory=lambda: [0.05, 0.20])  # m
    height_noise: float = 0.10  # m, uniform noise on the actor's heightmap (task layer)

    def check(self) -> None:
        check_range("difficulty.stairs_riser", self.stairs_riser)
        require(self.stairs_riser[0] > 0, "difficulty.stairs_riser", "must be > 0")
        require(self.stairs_tread > 0, "difficulty.stairs_tread", "must be > 0")
        check_range("difficulty.uneven_height", self.uneven_height)
        require(self.height_noise >= 0, "difficulty.height_noise", "must be >= 0")


@dataclass
class ResetConfig:
    joint_pos_noise: float = 0.05  # rad, uniform around home
    joint_vel_noise: float = 0.0
    base_xy_noise: float = 0.1  # m, uniform around the tile centre
    yaw_range: float = 3.14159  # rad; spawn heading uniform in [-yaw_range, yaw_range]


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


HARDWARE_TASKS = ("stair_ascent", "stair_descent", "hinged_ledge", "soft_ledge")


@dataclass
class StairTaskConfig:
    steps: int = 3  # a short flight (paper)
    riser: float = 0.18  # m, ~18 cm (paper)
    landing: float = 0.20  # m, tread depth: small ~20 cm landings (paper)
    skew_deg: float = 25.0  # stair edges rotated in the horizontal plane, ~25 deg (paper)


@dataclass
class HingedPlankConfig:
    """The hinged ledge: a plank balanced on a pivot that tips under load."""

    length: float = 1.2  # m
    width: float = 0.6
    thickness: float = 0.04
    pivot_height: float = 0.10  # m, plank centre above the ground when level
    tip_deg: float = 12.0  # hinge range: the plank tips this far either way
    mass: float = 6.0  # kg
    damping: float = 2.0  # N m s / rad
    # m between the ledge wall and the plank's near end, so a tipping plank clears it
    gap: float = 0.05
    # solver line-search iterations of this scene at least: at training's 5 (sim.ls_iterations)
    # a 20 kg load landing on the plank pushed it 12 degrees through the floor in one step
    ls_iterations: int = 20


@dataclass
class SoftMatConfig:
    """The soft ledge: a compliant gym mat (soft contact)."""

    length: float = 1.2  # m
    width: float = 1.0
    thickness: float = 0.10
    # time constant 4x MuJoCo's default, underdamped: it sinks under a foot
    solref: list[float] = field(default_factory=lambda: [0.08, 0.7])
    solimp: list[float] = field(default_factory=lambda: [0.3, 0.9, 0.06, 0.5, 2.0])


@group("hardware")
@dataclass
class HardwareConfig:
    """The paper's four hardware tasks, rebuilt in simulation (section Hardware Experiments)."""

    name: str = "default"
    tasks: list[str] = field(default_factory=lambda: list(HARDWARE_TASKS))
    trials: int = 5  # per policy and task (paper)
    command_x: float = 0.3  # m/s forward from a standing start (paper)
    time_limit_s: float = 20.0
    approach: float = 1.0  # m of flat ground (or platform) before the feature
    goal_past: float = 0.6  # m past the feature's end that counts as completed
    ledge_drop: float = 0.36  # m, elevation change of both ledges (paper)
    resolution: float = 0.01  # m, samples of the static geometry (previews, heightfield)
    # strips: the static geometry as rotated boxes, exact risers (the depth cameras' rays
    # cost microseconds); heightfield: its 1 cm samples (rays far slower: lca.bench hardware)
    representation: str = "strips"
    stairs: StairTaskConfig = field(default_factory=StairTaskConfig)
    plank: HingedPlankConfig = field(default_factory=HingedPlankConfig)
    mat: SoftMatConfig = field(default_factory=SoftMatConfig)

    def check(self) -> None:
        for task in self.tasks:
            require(
                task in HARDWARE_TASKS,
                "hardware.tasks",
                f"unknown '{task}'; allowed: {HARDWARE_TASKS}",
            )
        require(self.trials >= 1, "hardware.trials", "must be >= 1")
        allowed = ("strips", "heightfield")
        require(
            self.representation in allowed,
            "hardware.representation",
            f"unknown '{self.representation}'; allowed: {allowed}",
        )
