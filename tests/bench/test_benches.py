"""The throughput benchmarks (`python -m lca.bench sim|env|train`) run end to end at toy
sizes and report what they claim: rates from real stepping, ratios against their baseline
measured in the same run, and a verdict that follows the target."""

from __future__ import annotations

import pytest

from lca.bench import env, sim, train
from lca.bench.__main__ import result_name

pytestmark = pytest.mark.slow  # steps the physics and trains: see README

SMALL = ["scale=smoke", "terrain=flat"]


def test_sim_bench_measures_both_loops(monkeypatch) -> None:
    monkeypatch.setattr(sim, "NUM_ENVS", (8,))
    monkeypatch.setattr(sim, "THREADS", (1, 2))
    monkeypatch.setattr(sim, "REPEATS", 1)
    monkeypatch.setattr(sim, "MIN_SECONDS", 0.05)
    lines: list[str] = []
    result = sim.run(SMALL, log=lines.append)
    assert result["single_steps_per_s"] > 100  # a G1 steps far faster than 100 Hz here
    assert [(r["num_envs"], r["threads"]) for r in result["batched"]] == [(8, 1), (8, 2)]
    assert all(r["steps_per_s"] > 100 for r in result["batched"])
    assert lines[0].startswith("single mj_step loop:")


def test_sim_verdict_follows_the_target() -> None:
    rows = [{"num_envs": 256, "threads": 2, "steps_per_s": 1700.0}]
    assert "1.70x (meets)" in sim.table({"single_steps_per_s": 1000.0, "batched": rows})
    rows[0]["steps_per_s"] = 1500.0
    assert "1.50x (MISSES)" in sim.table({"single_steps_per_s": 1000.0, "batched": rows})


def test_env_bench_measures_env_against_raw_physics(monkeypatch) -> None:
    monkeypatch.setattr(sim, "NUM_ENVS", (8,))
    monkeypatch.setattr(sim, "THREADS", (1,))
    monkeypatch.setattr(env, "REPEATS", 1)
    monkeypatch.setattr(env, "MIN_SECONDS", 0.05)
    result = env.run(SMALL, log=None)
    (row,) = result["batched"]
    assert row["steps_per_s"] > 10 and row["raw_steps_per_s"] > 10
    assert row["ratio"] == pytest.approx(row["steps_per_s"] / row["raw_steps_per_s"])
    assert 0 < row["ratio"] < 1.5  # the task adds work on top of the same physics
    assert result["max_rss_mb"] > 100


def test_warp_backend_benches_over_worlds(monkeypatch) -> None:
    pytest.importorskip("mujoco_warp", reason="the gpu extra")
    monkeypatch.setattr(sim, "WARP_CPU_ENVS", (2,))
    monkeypatch.setattr(sim, "REPEATS", 1)
    monkeypatch.setattr(sim, "MIN_SECONDS", 0.05)
    monkeypatch.setattr(env, "REPEATS", 1)
    monkeypatch.setattr(env, "MIN_SECONDS", 0.05)
    warp = [*SMALL, "sim.backend=warp", "sim.warp_device=cpu"]
    lines: list[str] = []
    physics = sim.run(warp, log=lines.append)
    assert physics["backend"] == "warp" and [r["num_envs"] for r in physics["batched"]] == [2]
    assert physics["batched"][0]["steps_per_s"] > 10 and lines[-1].startswith("warp N=")
    measured = env.run(warp, log=None)
    (row,) = measured["batched"]
    assert 0 < row["ratio"] < 1.5
    plain = {"backend": "mjbatch"}
    assert (
        result_name("env", measured) == "env_warp.json" and result_name("env", plain) == "env.json"
    )


def test_env_verdict_follows_the_target() -> None:
    row = {"num_envs": 256, "threads": 2, "steps_per_s": 800.0, "raw_steps_per_s": 1000.0}
    row |= {"ratio": 0.8, "memory_mb_per_env": 0.1}
    assert "ratio >= 0.8: 0.80 (meets)" in env.table({"max_rss_mb": 900, "batched": [row]})
    row["ratio"] = 0.79
    assert "(MISSES)" in env.table({"max_rss_mb": 900, "batched": [row]})


def test_train_bench_splits_an_iteration_and_measures_its_baseline(monkeypatch) -> None:
    monkeypatch.setattr(train, "ITERATIONS", 2)
    result = train.run([*SMALL, "curriculum=blind", "encoder=mlp"], log=None)
    for r in (result, result["baseline"]):
        assert r["iterations"] == 2
        assert r["iteration_s"] == pytest.approx(r["collect_s"] + r["update_s"], rel=0.5)
        assert 0 < r["update_fraction"] < 1
    assert result["baseline"]["learning_epochs"] == 5  # rsl-rl's default, the baseline
    text = train.table(result)
    assert "target: update <= 25 % of an iteration" in text and "baseline" in text


def test_evaluate_bench_times_one_and_two_policies_at_a_time() -> None:
    from lca.bench import evaluate

    small = ["scale=smoke", "eval.units=2", "eval.steps=10", "eval.videos=false"]
    small.append("eval.cells=[{terrain: flat, difficulty: medium}]")
    result = evaluate.run(["shipped=blind_flat,blind_flat", *small], log=None)
    assert list(result["policies"]) == ["blind", "one_mlp"]  # the reference file's names
    assert result["baseline_s"] > 0 and result["current_s"] > 0
    assert result["speedup"] == pytest.approx(result["baseline_s"] / result["current_s"])
    assert "2 at a time, 1 thread each" in evaluate.table(result)
    assert result["arms"]["baseline"] == {"jobs": 1, "overrides": []}

    against = evaluate.run(
        ["shipped=blind_flat", "jobs=1", "baseline=eval.grid=[1,1]", *small], log=None
    )
    assert against["arms"] == {
        "baseline": {"jobs": 1, "overrides": ["eval.grid=[1,1]"]},
        "current": {"jobs": 1, "overrides": []},
    }
    assert "with eval.grid=[1,1] (1 at a time)" in evaluate.table(against)


def test_floor_bench_scales_each_part_to_the_shipped_evaluation() -> None:
    import pandas as pd

    from lca.bench import floor
    from lca.paths import assets_dir

    cells = "eval.cells=[{terrain: flat, difficulty: medium}, {terrain: uneven, difficulty: hard}]"
    result = floor.run(["shipped=blind", "steps=3", "eval.units=4", cells], log=None)
    shipped = pd.read_parquet(assets_dir() / "policies" / "blind" / "results.parquet")
    assert [row["cell"] for row in result["cells"]] == ["flat-medium", "uneven-hard"]
    for row in result["cells"]:
        terrain, difficulty = row["cell"].split("-")
        cell = shipped[(shipped.cell_terrain == terrain) & (shipped.cell_difficulty == difficulty)]
        assert row["physics_s"] == pytest.approx(row["physics_per_unit_step"] * cell.steps.sum())
        rounds = cell.groupby("episode").steps.max().sum()  # a round runs to its last unit
        assert row["actor_s"] == pytest.approx(row["actor_per_step"] * rounds)
        assert 0 < row["physics_share"] < 1
    totals = result["totals_s"]
    assert result["floor_min"] == pytest.approx(totals["physics"] / 2 / 60)
    assert result["cells_min"] == pytest.approx(sum(totals.values()) / 2 / 60)
    assert "physics alone (the floor)" in floor.table(result)


def test_hardware_bench_times_both_ground_representations_on_the_same_trials() -> None:
    from lca.bench import hardware

    small = ["hardware.trials=1", "hardware.time_limit_s=0.2", "hardware.tasks=[soft_ledge]"]
    result = hardware.run(["shipped=one_mlp", *small], log=None)
    row = result["tasks"]["soft_ledge"]
    assert row["heightfield_s"] > 0 and row["strips_s"] > 0
    assert result["speedup"] == pytest.approx(result["heightfield_s"] / result["strips_s"])
    assert "| soft_ledge |" in hardware.table(result)


def test_clips_bench_films_one_recording_with_both_grounds() -> None:
    from lca.bench import clips
    from lca.sim.render import gl_unavailable

    if gl_unavailable():
        pytest.skip(f"MuJoCo cannot render here: {gl_unavailable()}")
    one = ["eval.cells=[{terrain: uneven, difficulty: medium}]", "eval.video_seconds=0.2"]
    result = clips.run([*one, "frames=3"], log=None)
    assert result["clips"] == 1
    ((cell, costs),) = result["frames"].items()
    assert cell == "uneven-medium" and costs["crop_ms"] > 0 and costs["window_ms"] > 0
    assert result["frame_speedup"] == pytest.approx(costs["crop_ms"] / costs["window_ms"])
    assert "| uneven-medium |" in clips.table(result)
