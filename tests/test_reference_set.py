"""The reference set (issue 28): experiments/reference.yaml, `scale=reference`, and
`python -m lca.experiment <file> --evaluate-only` on shipped policies."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pandas as pd
import pytest
from omegaconf import OmegaConf

from lca import experiment
from lca.config import compose
from lca.evaluate.policy import final_checkpoint, load_run_config
from lca.evaluate.protocol import discard_stale_rounds
from lca.paths import root
from lca.shipped import evaluated_copy, shipped_name, shipped_runs

REFERENCE = root() / "experiments" / "reference.yaml"
BLIND_FLAT = root() / "assets" / "policies" / "blind_flat"


def test_the_file_states_the_budget_the_recipe_trains():
    spec = OmegaConf.to_container(OmegaConf.load(REFERENCE))
    for policy in spec["policies"]:
        cfg = compose([f"policy={policy}", *spec["overrides"]])
        steps = cfg.scale.max_iterations * cfg.algo.num_steps_per_env * cfg.task.num_envs
        assert steps == spec["budget_env_steps"], policy
        assert cfg.terrain.name == "mixed" and cfg.seed == 0
        assert cfg.eval.units >= 128 and cfg.eval.episodes >= 2 and cfg.eval.steps >= 1000
    # the common warm start of the decision rule ships with the repository
    start = compose(spec["overrides"]).algo.init_from
    assert (root() / start).is_file()


def test_every_policy_uses_the_paper_cnn_and_full_body_collisions():
    cfg = compose(["policy=two_cnn", "scale=reference"])
    assert cfg.encoder.pool == 0
    assert set(cfg.robot.collision_parts) == {"feet", "legs", "torso", "arms"}


def _ship(shipped: Path, name: str, seed: int = 0) -> None:
    """A copy of the flat walker shipped as policy `name`'s training seed `seed`: the blind
    MLP's networks are those of an MLP-encoder policy of any curriculum (its encoder
    untrained)."""
    folder = shipped / shipped_name(name, seed)
    shutil.copytree(BLIND_FLAT, folder, ignore=shutil.ignore_patterns("*.onnx", "*.jit", "*.pt2"))
    cfg = OmegaConf.load(folder / "config.yaml")
    named = compose([f"policy={name}"])
    cfg.curriculum, cfg.policy, cfg.seed = named.curriculum, named.policy, seed
    OmegaConf.save(cfg, folder / "config.yaml")


@pytest.mark.slow  # evaluates: see README
def test_evaluate_only_reports_two_shipped_policies(tmp_path):
    shipped = tmp_path / "shipped"
    shipped.mkdir()
    shutil.copytree(BLIND_FLAT, shipped / "blind")
    _ship(shipped, "two_mlp")
    _ship(shipped, "two_mlp", seed=1)  # a second training seed ships beside the first
    spec = OmegaConf.to_container(OmegaConf.load(REFERENCE))
    spec |= {"shipped": str(shipped), "report": str(tmp_path / "report"), "hardware": True}
    spec["seeds"] = [0, 1]
    spec["overrides"] = ["scale=smoke", "eval.units=4", "eval.steps=30"]
    spec["overrides"] += [
        "hardware.trials=2",
        "hardware.time_limit_s=0.2",
        "hardware.tasks=[soft_ledge]",
    ]
    file = tmp_path / "reference.yaml"
    OmegaConf.save(OmegaConf.create(spec), file)

    # two policies at once, each in a process of its own (the reference file's setting)
    runs = f"runs_root={tmp_path / 'runs'}"
    code = experiment.main([str(file), "--evaluate-only", "--jobs", "2", runs])
    assert code == 0
    report = tmp_path / "report"
    table = pd.read_csv(report / "sim_table.csv")
    assert list(dict.fromkeys(table["policy"])) == ["Blind", "Two-Stage MLP"]
    cells = {(t, d) for t in ("stairs", "uneven") for d in ("medium", "hard")}
    metrics = {"success", "contacts_per_step", "track_cm_s"}
    for policy, rows in table.groupby("policy"):
        assert set(zip(rows["terrain"], rows["difficulty"], strict=True)) == cells
        seeds = 2 if policy == "Two-Stage MLP" else 1  # its two seeds' units pooled
        assert set(rows["metric"]) == metrics and (rows["n_units"] == 4 * seeds).all()
        assert (rows["n_seeds"] == seeds).all()
    assert (report / "claim.csv").is_file()  # the paired two-stage - one-stage comparison
    assert json.loads((report / "evaluate_only.json").read_text())["rounds_reused"] == 0
    assert (report / "sim_table.tex").is_file() and (report / "index.html").is_file()
    assert "Between 1 and 2 training seeds per row" in (report / "index.html").read_text()
    training = pd.read_csv(report / "training.csv")
    assert list(zip(training["policy"], training["seed"], strict=True)) == [
        ("blind", 0),
        ("two_mlp", 0),
        ("two_mlp", 1),
    ]
    curve = pd.read_csv(BLIND_FLAT / "train_curve.csv").iloc[-1]
    assert training["env_steps"].tolist() == [int(curve["env_steps"])] * 3
    assert (tmp_path / "runs" / "evaluated" / "blind" / "summary.csv").is_file()
    evaluated = OmegaConf.load(tmp_path / "runs" / "evaluated" / "two_mlp" / "config.yaml")
    assert evaluated.sim.num_threads == 1
    # the hardware-style tasks ran beside the cells, in copies of their own, then joined
    evaluated = ["blind", "two_mlp", "two_mlp-seed1"]
    for name in evaluated:
        trials = pd.read_csv(tmp_path / "runs" / "evaluated" / name / "hardware.csv")
        assert list(trials["task"]) == ["soft_ledge"] * 2
    assert sorted(p.name for p in (tmp_path / "runs" / "evaluated").iterdir()) == evaluated
    assert set(pd.read_csv(report / "hardware_table.csv")["policy"]) >= {"Blind", "Two-Stage MLP"}


def _mark_shipped(shipped: Path, policy: str, seed: int, trained_seed: int | None = None) -> None:
    folder = shipped / shipped_name(policy, seed)
    folder.mkdir(parents=True)
    (folder / "COMPLETE").touch()
    OmegaConf.save({"seed": seed if trained_seed is None else trained_seed}, folder / "config.yaml")


def test_a_shipped_policy_is_not_trained_again(tmp_path, capsys):
    shipped = tmp_path / "shipped"
    _mark_shipped(shipped, "blind", 0)
    _mark_shipped(shipped, "two_mlp", 1)
    spec = OmegaConf.to_container(OmegaConf.load(REFERENCE))
    spec |= {"shipped": str(shipped), "seeds": [0, 1]}
    file = tmp_path / "reference.yaml"
    OmegaConf.save(OmegaConf.create(spec), file)
    assert experiment.main([str(file), "--dry-run"]) == 0
    out = capsys.readouterr().out
    assert "shipped already, not trained again: blind, two_mlp-seed1" in out
    planned = [tuple(line.split()[:2]) for line in out.splitlines() if line.startswith("  policy=")]
    expected = [
        (f"policy={p}", f"seed={s}")
        for s in (0, 1)
        for p in spec["policies"]
        if (p, s) not in {("blind", 0), ("two_mlp", 1)}
    ]
    assert sorted(planned) == sorted(expected)
    # a multirun is a product of policies and seeds: one per seed that misses others
    commands = [line for line in out.splitlines() if line.startswith("command:")]
    seeds = [next(t for t in c.split() if t.startswith("seed=")) for c in commands]
    assert seeds == ["seed=0", "seed=1"]


def test_a_shipped_folder_must_hold_the_seed_its_name_says(tmp_path):
    shipped = tmp_path / "shipped"
    _mark_shipped(shipped, "one_mlp", 1, trained_seed=0)
    spec = {"policies": ["one_mlp"], "seeds": [0, 1], "shipped": str(shipped)}
    named = "one_mlp-seed1: its run trained seed 0, its name says seed 1"
    with pytest.raises(ValueError, match=named):
        shipped_runs(spec)


def test_the_default_job_shows_the_shipped_reference_policies() -> None:
    """The default job's report has the flat walker's rows and the reference set's blind
    policy's, each under its own label."""
    cfg = compose([])
    assert list(cfg.eval.reference) == ["blind_flat", "blind"]
    for name in cfg.eval.reference:
        assert (root() / "assets" / "policies" / name / "COMPLETE").is_file(), name


def test_an_evaluated_copy_keeps_its_rounds_only_from_the_same_origin(tmp_path):
    """A second --evaluate-only goes on from the first one's finished rounds, unless the
    checkpoint or the thread count (both change results) differ."""
    shipped = tmp_path / "shipped"
    _ship(shipped, "two_mlp")
    out = tmp_path / "runs" / "evaluated" / "two_mlp"

    def copy_and_stamp(threads: int) -> None:
        """What an --evaluate-only part does before its rounds: the copy, then the stamp."""
        evaluated_copy("two_mlp", shipped / "two_mlp", out, ["scale=smoke"], threads=threads)
        cfg = load_run_config(out)
        discard_stale_rounds(out / "eval", cfg, final_checkpoint(out), log=None)

    copy_and_stamp(threads=1)
    finished = out / "eval" / "stairs-medium" / "episode_0.csv"
    finished.parent.mkdir(parents=True)
    finished.write_text("unit\n0\n")

    copy_and_stamp(threads=1)
    assert finished.read_text() == "unit\n0\n"
    assert OmegaConf.load(out / "config.yaml").sim.num_threads == 1

    copy_and_stamp(threads=2)
    assert not finished.exists()  # another thread count: evaluated afresh
    finished.parent.mkdir(parents=True)
    finished.write_text("unit\n0\n")
    checkpoint = next((shipped / "two_mlp" / "checkpoints").glob("*.pt"))
    checkpoint.write_bytes(checkpoint.read_bytes() + b"\0")
    copy_and_stamp(threads=2)
    assert not finished.exists()  # another checkpoint: evaluated afresh
