"""Config group of the evaluation protocol: units, episodes, steps and cells."""

from __future__ import annotations

from dataclasses import dataclass, field

from omegaconf import MISSING, OmegaConf

from lca.config.errors import check_range, require
from lca.config.registry import eval_terrain_names
from lca.config.schema import ConfigValueError, group
from lca.paths import assets_dir, conf_dir


def difficulties() -> list[str]:
    """The difficulty options (conf/difficulty/*.yaml): what an evaluation cell may name."""
    return sorted(p.stem for p in (conf_dir() / "difficulty").glob("*.yaml"))


def shipped_policies() -> list[str]:
    """The complete runs under assets/policies/: what `eval.reference` may name."""
    return sorted(p.parent.name for p in (assets_dir() / "policies").glob("*/COMPLETE"))


@dataclass
class EvalCell:
    terrain: str = MISSING  # stairs (= half up, half down) | uneven | flat | stairs_up | ...
    difficulty: str = MISSING  # medium | hard


@group("eval")
@dataclass
class EvalConfig:
    """The paper's protocol: U units x E episodes x T steps per cell, forward commands, the
    difficulty's heightmap noise. The paper's sizes (500 x 3 x 1000) are set by scale=paper."""

    name: str = "default"
    units: int = 32  # simulated robots per cell (paper: 500)
    episodes: int = 2  # episodes per unit (paper: 3)
    steps: int = 500  # policy steps per episode (paper: 1000)
    # rows x cols tiles of each round's terrain (every cell and episode round draws its own):
    # 16 draws of riser or block field per round, whatever grid the policy trained on
    grid: list[int] = field(default_factory=lambda: [4, 4])
    # shipped policies (assets/policies/<name>) evaluated with these settings beside a run in
    # its report, marked "(reference: <name>)"; each evaluation is cached under
    # runs_root/.reference. The flat walker and the reference set's blind policy (issue 28)
    reference: list[str] = field(default_factory=lambda: ["blind_flat", "blind"])
    cells: list[EvalCell] = field(  # stairs = half the tiles up, half down
        default_factory=lambda: [
            EvalCell(t, d) for t in ("stairs", "uneven") for d in ("medium", "hard")
        ]
    )
    # m/s forward, inside the training range; lateral and yaw commands zero
    command_x: list[float] = field(default_factory=lambda: [0.3, 0.6])
    seed: int = 12345
    bootstrap_resamples: int = 2000
    confidence: float = 0.95
    videos: bool = True  # after evaluation: a clip per cell and terrain previews (needs GL)
    video_seconds: float = 4.0  # length of each cell's clip

    def check(self) -> None:
        for key in ("units", "episodes", "steps"):
            require(getattr(self, key) >= 1, f"eval.{key}", "must be >= 1")
        require(
            len(self.grid) == 2 and min(self.grid) >= 1,
            "eval.grid",
            f"must be [rows, cols] >= 1, got {list(self.grid)}",
        )
        shipped = shipped_policies()
        for name in self.reference:
            require(
                name in shipped,
                "eval.reference",
                f"no shipped policy '{name}'; shipped (assets/policies/): {shipped}",
            )
        require(
            self.video_seconds > 0, "eval.video_seconds", f"must be > 0, got {self.video_seconds}"
        )
        allowed, levels = eval_terrain_names(), difficulties()
        for i, cell in enumerate(self.cells):
            require(
                cell.terrain in allowed,
                f"eval.cells[{i}].terrain",
                f"unknown evaluation terrain '{cell.terrain}'; allowed: {allowed}",
            )
            require(
                cell.difficulty in levels,
                f"eval.cells[{i}].difficulty",
                f"unknown '{cell.difficulty}'; allowed: {levels}",
            )
        check_range("eval.command_x", self.command_x, -1e9)


def parse_cell(text: str) -> EvalCell:
    """'stairs-hard' -> the EvalCell (terrain, difficulty), checked as the eval config checks
    its cells; ConfigValueError (lca.config.ConfigError) naming the allowed values."""
    terrain, _, difficulty = text.rpartition("-")
    cell = EvalCell(terrain or text, difficulty)
    try:
        EvalConfig(cells=[cell]).check()
    except ConfigValueError as error:
        raise ConfigValueError(
            f"cell: '{text}' is not <terrain>-<difficulty> (e.g. stairs-hard): {error}"
        ) from None
    return OmegaConf.structured(cell)
