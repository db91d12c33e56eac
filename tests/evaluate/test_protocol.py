"""The evaluation protocol on a real (tiny) trained run: each cell's setting, one round's
accounting, the results files, and resuming an interrupted evaluation without double counting.
"""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import torch
from omegaconf import OmegaConf

from lca.config.registry import EVAL_TERRAINS, TILES
from lca.evaluate.__main__ import main as evaluate_main
from lca.evaluate.metrics import METRICS
from lca.evaluate.protocol import (
    cell_config,
    cell_name,
    difficulty_config,
    round_seed,
    run_round,
)
from lca.evaluate.rollout import step_only
from lca.evaluate.run import evaluate_and_write
from lca.sim.terrain import generate
from lca.task.env import LocomotionEnv
from lca.testhook import KILLED

from .helpers import (
    EPISODES,
    POLICY_DT,
    STEPS,
    UNITS,
    cli_env,
    episode_files,
    evaluate_command,
    run_evaluate_cli,
    smoke_cfg,
    sort_episodes,
    train_tiny_run,
)

PAPER_CELLS = [("stairs", "medium"), ("stairs", "hard"), ("uneven", "medium"), ("uneven", "hard")]
RESULT_COLUMNS = {
    "run",
    "cell_terrain",
    "cell_difficulty",
    "unit",
    "episode",
    "success",
    "steps",
    "contacts_per_step",
    "track_cm_s",
    "command_x",
}

pytestmark = pytest.mark.slow  # trains and evaluates runs: see README


@pytest.fixture(scope="module")
def cfg():
    return smoke_cfg()


def _cell(cfg, terrain: str, difficulty: str):
    return next(c for c in cfg.eval.cells if (c.terrain, c.difficulty) == (terrain, difficulty))


# ---- the setting of one cell -------------------------------------------------------------


def test_default_cells_are_the_papers(cfg) -> None:
    assert [(c.terrain, c.difficulty) for c in cfg.eval.cells] == PAPER_CELLS
    assert list(cfg.eval.command_x) == [0.3, 0.6]


PAPER_DIFFICULTY = {
    "medium": {
        "name": "medium",
        "stairs_riser": [0.14, 0.18],
        "stairs_tread": 0.31,
        "uneven_height": [0.05, 0.20],
        "height_noise": 0.10,
    },
    "hard": {
        "name": "hard",
        "stairs_riser": [0.16, 0.20],
        "stairs_tread": 0.23,
        "uneven_height": [0.05, 0.40],
        "height_noise": 0.30,
    },
}


@pytest.mark.parametrize(("terrain", "difficulty"), PAPER_CELLS)
def test_cell_config(cfg, terrain: str, difficulty: str) -> None:
    c = cell_config(cfg, _cell(cfg, terrain, difficulty))
    mixture = dict(c.terrain.mixture)  # replaced whole: the run's own mixture is gone
    if terrain == "stairs":
        assert mixture == {"stairs_up": 0.5, "stairs_down": 0.5}
    else:
        assert mixture == {"uneven": 1.0}
    # the paper's table "Environment parameters" for the cell's difficulty, whatever the run
    # trained on
    assert OmegaConf.to_container(c.difficulty) == PAPER_DIFFICULTY[difficulty]
    assert c.task.num_envs == UNITS
    assert c.task.episode_length_s == pytest.approx(STEPS * POLICY_DT)
    assert c.sim.timestep * c.sim.decimation == pytest.approx(POLICY_DT)
    assert round(c.task.episode_length_s / (c.sim.timestep * c.sim.decimation)) == STEPS
    assert c.task.randomization.enabled is False
    commands = c.task.commands
    assert list(commands.lin_vel_x) == list(cfg.eval.command_x)
    assert 0 < commands.lin_vel_x[0] <= commands.lin_vel_x[1]  # forward only
    assert list(commands.lin_vel_y) == [0.0, 0.0] and list(commands.ang_vel_z) == [0.0, 0.0]
    assert commands.standing_fraction == 0.0
    assert commands.resample_time_s > c.task.episode_length_s  # one command per episode


def test_each_round_draws_its_own_terrain(cfg) -> None:
    """A cell's rounds meet different tiles, drawn from the eval seed alone: the same for
    every policy, whatever seed it trained with."""
    cell = _cell(cfg, "stairs", "hard")
    risers = [
        [t.params["riser"] for t in generate(c.terrain, c.difficulty).tiles]
        for c in (cell_config(cfg, cell, episode) for episode in (0, 1))
    ]
    assert risers[0] != risers[1]
    other = cfg.copy()
    other.seed, other.terrain.seed = 7, 99
    again = cell_config(other, cell, 1)
    assert [t.params["riser"] for t in generate(again.terrain, again.difficulty).tiles] == (
        risers[1]
    )


def test_cell_config_leaves_the_run_config_alone(cfg) -> None:
    before = OmegaConf.to_yaml(cfg)
    cell_config(cfg, _cell(cfg, "uneven", "hard"))
    assert OmegaConf.to_yaml(cfg) == before
    assert cfg.task.num_envs == 8 and cfg.task.randomization.enabled


def test_cell_config_difficulty_replaces_the_trained_one() -> None:
    hard_run = smoke_cfg("difficulty=hard")
    c = cell_config(hard_run, _cell(hard_run, "stairs", "medium"))
    assert c.difficulty == difficulty_config("medium")
    assert c.difficulty.stairs_tread == pytest.approx(0.31)


@pytest.mark.parametrize(("terrain", "difficulty"), PAPER_CELLS)
def test_cell_terrain_tiles(cfg, terrain: str, difficulty: str) -> None:
    """The terrain built for a cell: stairs = half the tiles up, half down, with the cell's
    riser range and tread; uneven = only block fields with the cell's height range."""
    c = cell_config(cfg, _cell(cfg, terrain, difficulty))
    tiles = generate(c.terrain, c.difficulty).tiles
    kinds = [t.kind for t in tiles]
    d = OmegaConf.create(PAPER_DIFFICULTY[difficulty])
    if terrain == "stairs":
        assert sorted(kinds) == sorted(["stairs_up", "stairs_down"] * (len(tiles) // 2))
        for tile in tiles:
            assert d.stairs_riser[0] <= tile.params["riser"] <= d.stairs_riser[1]
            assert tile.params["tread"] == pytest.approx(d.stairs_tread)
    else:
        assert set(kinds) == {"uneven"}
        for tile in tiles:
            assert (tile.params["low"], tile.params["high"]) == tuple(d.uneven_height)


def test_cell_mixtures_are_distributions() -> None:
    for name, mixture in EVAL_TERRAINS.items():
        assert set(mixture) <= set(TILES.names()), name
        assert sum(mixture.values()) == pytest.approx(1.0), name


def test_round_seeds_differ_per_cell_and_round(cfg) -> None:
    seeds = [round_seed(cfg.eval.seed, c, e) for c in cfg.eval.cells for e in range(3)]
    assert len(set(seeds)) == len(seeds)
    other_run = smoke_cfg("seed=7")  # a run's own seed does not enter the round seed
    cells = other_run.eval.cells
    assert seeds == [round_seed(other_run.eval.seed, c, e) for c in cells for e in range(3)]


# ---- one round ---------------------------------------------------------------------------


class FoldLegs:
    """A scripted actor (not the policy under test): every joint at -1, the robot collapses."""

    def __init__(self, env: LocomotionEnv):
        self.shape = (env.num_envs, env.num_actions)

    def __call__(self, obs) -> torch.Tensor:
        return torch.full(self.shape, -1.0)

    def reset(self, dones) -> None:
        pass


def test_run_round_stops_counting_at_first_termination() -> None:
    """Units that fall: success 0, their steps are those before the fall (not the whole round;
    the env resets them and they stand frozen), and the per-step metrics are over those
    steps only: the same numbers as stepping the env by hand."""
    steps = 150
    cfg = smoke_cfg(f"eval.steps={steps}")
    env = LocomotionEnv(cell_config(cfg, _cell(cfg, "uneven", "hard")))
    actor = FoldLegs(env)
    env.reseed(99)
    out = run_round(env, actor, steps)
    assert (out["success"] == 0).all()
    assert ((out["steps"] >= 1) & (out["steps"] < steps)).all(), out["steps"]

    env.reseed(99)
    env.reset_all()
    n = env.num_envs
    first_end = np.full(n, -1)
    impacts, track = np.zeros(n), np.zeros(n)
    command_x = env.commands.value[:, 0].copy()
    for t in range(steps):
        _, _, _, extras = env.step(actor(None))
        m = extras["metrics"]
        alive = first_end < 0
        impacts += alive & m["lateral_impact"]
        track += np.where(alive, m["track_error"], 0.0)
        first_end[alive & (m["terminated"] | m["time_out"])] = t + 1
        if (first_end > 0).all():
            break
        step_only(env, first_end < 0)
    np.testing.assert_array_equal(out["steps"], first_end)
    np.testing.assert_allclose(out["contacts_per_step"], 100 * impacts / first_end)
    np.testing.assert_allclose(out["track_cm_s"], 100 * track / first_end)
    np.testing.assert_array_equal(out["command_x"], command_x)
    assert ((command_x >= 0.3) & (command_x <= 0.6)).all()


def test_units_that_no_longer_count_cost_no_physics() -> None:
    """`step_only`: the physics steps the units still counted; the others stand frozen."""
    cfg = smoke_cfg()
    env = LocomotionEnv(cell_config(cfg, _cell(cfg, "stairs", "medium")))
    actor = FoldLegs(env)
    env.reseed(5)
    env.reset_all()
    counted = np.arange(env.num_envs) % 2 == 0
    step_only(env, counted)
    before = np.array(env.sim.qpos, copy=True)
    for _ in range(3):
        env.step(actor(None))
    moved = np.any(np.asarray(env.sim.qpos) != before, axis=1)
    np.testing.assert_array_equal(moved, counted)
    env.reset_all()  # a new round steps every unit again
    assert env.stepping is None


# ---- a real evaluation -------------------------------------------------------------------


def test_evaluation_results_files(evaluated_run) -> None:
    cfg, run_dir, summary = evaluated_run
    cells = len(cfg.eval.cells)
    for path in episode_files(run_dir, cfg):
        frame = pd.read_csv(path)
        assert list(frame["unit"]) == list(range(UNITS)), path
        assert frame["episode"].nunique() == 1, path

    results = pd.read_parquet(run_dir / "results.parquet")
    assert set(results.columns) == RESULT_COLUMNS
    assert len(results) == UNITS * EPISODES * cells
    assert (results["run"] == run_dir.name).all()
    keys = ["cell_terrain", "cell_difficulty", "episode", "unit"]
    assert not results.duplicated(keys).any()
    per_cell = results.groupby(["cell_terrain", "cell_difficulty"]).size()
    assert sorted(per_cell.index) == sorted(PAPER_CELLS)
    assert (per_cell == UNITS * EPISODES).all()

    # each episode: success in {0, 100}; a success lasted exactly eval.steps policy steps
    assert set(results["success"]) <= {0.0, 100.0}
    assert results["steps"].between(1, STEPS).all()
    assert (results.loc[results.success == 100, "steps"] == STEPS).all()
    assert (results.loc[results.success == 0, "steps"] < STEPS).all()
    assert results["contacts_per_step"].between(0, 100).all()
    assert (results["track_cm_s"] >= 0).all() and np.isfinite(results["track_cm_s"]).all()
    # forward commands inside eval.command_x; each round draws its own
    assert results["command_x"].between(*cfg.eval.command_x).all()
    rounds = results.groupby(["cell_terrain", "cell_difficulty", "episode"])["command_x"]
    assert rounds.apply(tuple).nunique() == cells * EPISODES

    on_disk = pd.read_csv(run_dir / "summary.csv")
    assert len(on_disk) == cells * len(METRICS)
    pd.testing.assert_frame_equal(on_disk, summary, check_dtype=False)
    assert (on_disk["n_units"] == UNITS).all() and (on_disk["n_episodes"] == UNITS * EPISODES).all()
    for row in on_disk.itertuples():
        cell = results[
            (results.cell_terrain == row.cell_terrain)
            & (results.cell_difficulty == row.cell_difficulty)
        ]
        units = cell.groupby("unit")[row.metric].mean()
        assert row.mean == pytest.approx(units.mean())
        assert row.se == pytest.approx(units.std(ddof=1) / np.sqrt(UNITS))
        assert row.ci_low <= row.mean + 1e-9 and row.mean <= row.ci_high + 1e-9


def _copy_run(run_dir: Path, tmp_path: Path) -> Path:
    """The evaluated run under the same folder name (results carry it in their `run` column)."""
    copy = tmp_path / run_dir.name
    shutil.copytree(run_dir, copy)
    return copy


def _eval_lines(stdout: str) -> list[str]:
    return [line for line in stdout.splitlines() if line.startswith("[lca] eval")]


def test_resume_after_a_lost_round(evaluated_run, tmp_path) -> None:
    """Delete one round's file, run `python -m lca.evaluate` again: only that round runs, the
    other files are untouched, the round comes back identical (seeded per round) and
    results.parquet holds every episode exactly once."""
    cfg, run_dir, _ = evaluated_run
    copy = _copy_run(run_dir, tmp_path)
    files = episode_files(copy, cfg)
    lost = copy / "eval" / cell_name(cfg.eval.cells[2]) / "episode_1.csv"
    assert lost in files
    original = lost.read_bytes()
    lost.unlink()
    mtimes = {p: p.stat().st_mtime_ns for p in files if p != lost}

    out = run_evaluate_cli(copy, cwd=tmp_path)
    assert out.returncode == 0, out.stdout + out.stderr
    lines = _eval_lines(out.stdout)
    assert len(lines) == 1 and f"{cell_name(cfg.eval.cells[2])} episode 2/{EPISODES}" in lines[0]
    assert {p: p.stat().st_mtime_ns for p in mtimes} == mtimes
    assert lost.read_bytes() == original

    results = pd.read_parquet(copy / "results.parquet")
    assert len(results) == UNITS * EPISODES * len(cfg.eval.cells)
    expected = pd.read_parquet(run_dir / "results.parquet")
    pd.testing.assert_frame_equal(sort_episodes(results), sort_episodes(expected))
    pd.testing.assert_frame_equal(
        pd.read_csv(copy / "summary.csv"), pd.read_csv(run_dir / "summary.csv")
    )


def test_resume_after_a_killed_evaluation(evaluated_run, tmp_path) -> None:
    """Kill `python -m lca.evaluate` after its first round, evaluate again: the finished
    rounds are kept, the rest are run once, and the results equal an uninterrupted evaluation."""
    cfg, run_dir, _ = evaluated_run
    copy = _copy_run(run_dir, tmp_path)
    for stale in ("results.parquet", "summary.csv"):
        (copy / stale).unlink()
    shutil.rmtree(copy / "eval")
    files = episode_files(copy, cfg)

    # the test hook ends the evaluation like a SIGKILL right after its first round's file
    killed = subprocess.run(
        evaluate_command(copy),
        cwd=tmp_path,
        env=cli_env() | {"LCA_TEST_EXIT_AFTER": "round:1"},
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    assert killed.returncode == KILLED, killed.stdout[-2000:] + killed.stderr[-2000:]
    done = [p for p in files if p.exists()]
    assert done == files[:1], "exactly the first round is on disk"
    assert not (copy / "results.parquet").exists()
    mtimes = {p: p.stat().st_mtime_ns for p in done}

    lines: list[str] = []
    evaluate_and_write(copy, log=lines.append)
    assert len(_eval_lines("\n".join(lines))) == len(files) - len(done)
    assert {p: p.stat().st_mtime_ns for p in done} == mtimes
    results = pd.read_parquet(copy / "results.parquet")
    assert len(results) == UNITS * EPISODES * len(cfg.eval.cells)
    expected = pd.read_parquet(run_dir / "results.parquet")
    pd.testing.assert_frame_equal(sort_episodes(results), sort_episodes(expected))


def test_evaluate_cli_usage(tmp_path, capsys) -> None:
    assert evaluate_main([]) == 2
    assert "usage: python -m lca.evaluate run_dir=<dir>" in capsys.readouterr().err
    with pytest.raises(FileNotFoundError, match="config.yaml"):
        evaluate_main([f"run_dir={tmp_path}"])


def test_evaluate_needs_a_trained_policy(evaluated_run, tmp_path) -> None:
    _, run_dir, _ = evaluated_run
    untrained = tmp_path / "untrained"
    untrained.mkdir()
    shutil.copy(run_dir / "config.yaml", untrained / "config.yaml")
    with pytest.raises(FileNotFoundError, match="final_"):
        evaluate_main([f"run_dir={untrained}"])


def test_changed_protocol_does_not_reuse_old_rounds(evaluated_run, tmp_path) -> None:
    cfg, run_dir, _ = evaluated_run
    copy = _copy_run(run_dir, tmp_path)
    evaluate_and_write(copy, ["eval.steps=10", "eval.units=2"], log=None)  # a fresh protocol
    results = pd.read_parquet(copy / "results.parquet")
    assert results["steps"].max() <= 10
    assert len(results) == 2 * EPISODES * len(cfg.eval.cells)


ONE_CELL = "eval.cells=[{terrain:uneven,difficulty:hard}]"


@pytest.mark.parametrize("policy", ["blind", "one_lstm"])
def test_evaluate_other_architectures(policy: str, tmp_path) -> None:
    """A blind MLP and a recurrent actor evaluate too; a round evaluated on its own equals the
    same round evaluated after another one (the LSTM state is reset per round)."""
    cfg, run = train_tiny_run(tmp_path / policy, f"policy={policy}", ONE_CELL)
    assert cfg.curriculum.name == policy.split("_")[0] and len(cfg.eval.cells) == 1
    evaluate_and_write(run.path, log=None)
    results = pd.read_parquet(run.path / "results.parquet")
    assert len(results) == UNITS * EPISODES
    assert results["success"].isin([0.0, 100.0]).all() and np.isfinite(results["track_cm_s"]).all()
    second = episode_files(run.path, cfg)[1]
    original = second.read_bytes()
    second.unlink()
    evaluate_and_write(run.path, log=None)
    assert second.read_bytes() == original
