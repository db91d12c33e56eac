"""Config groups of the perception pipeline and the hardware-style tasks."""

from __future__ import annotations

from dataclasses import dataclass, field

from omegaconf import MISSING

from lca.config.errors import require


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
        require(self.source in allowed, "perception.source", f"allowed: {allowed}")
        require(
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
            require(
                task in HARDWARE_TASKS,
                "hardware.tasks",
                f"unknown '{task}'; allowed: {HARDWARE_TASKS}",
            )
        require(self.trials >= 1, "hardware.trials", "must be >= 1")
