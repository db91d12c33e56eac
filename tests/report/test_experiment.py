"""`python -m lca.experiment experiments/paper_sim.yaml --dry-run`: the paper's plan and cost."""

from __future__ import annotations

import json
import re
from itertools import product

import pytest
from omegaconf import OmegaConf

from lca import experiment
from lca.config import compose

from .helpers import REPO, run_python

pytestmark = pytest.mark.slow  # trains, evaluates or runs a stage: see README

PAPER_SIM = REPO / "experiments" / "paper_sim.yaml"
POLICIES = ["blind", "one_mlp", "two_mlp", "one_lstm", "two_lstm", "one_cnn", "two_cnn"]
SEEDS = [0, 1, 2]


def _dry_run(*args: str):
    out = run_python("-m", "lca.experiment", *args, cwd=REPO, timeout=60)
    assert out.returncode == 0, out.stdout + out.stderr
    return out.stdout


def _per_run_steps(stdout: str) -> tuple[int, int]:
    match = re.search(r"per run: ([\d,]+) training \+ ([\d,]+) evaluation env steps", stdout)
    assert match, stdout
    return tuple(int(g.replace(",", "")) for g in match.groups())


def _expected_steps(*overrides: str) -> tuple[int, int]:
    cfg = compose(["policy=blind", *overrides])
    train = cfg.scale.max_iterations * cfg.algo.num_steps_per_env * cfg.task.num_envs
    ev = cfg.eval
    return train, len(ev.cells) * ev.units * ev.episodes * ev.steps


def test_experiment_file() -> None:
    spec = OmegaConf.to_container(OmegaConf.load(PAPER_SIM))
    assert spec["policies"] == POLICIES and spec["seeds"] == SEEDS
    for policy in POLICIES:
        assert (REPO / "conf" / "policy" / f"{policy}.yaml").is_file(), policy


@pytest.fixture(scope="module")
def paper_plan() -> str:
    return _dry_run(str(PAPER_SIM), "--dry-run")


def test_dry_run_plans_21_runs(paper_plan: str) -> None:
    planned = re.findall(r"^  policy=(\w+) seed=(\d+) (.*)$", paper_plan, flags=re.M)
    assert [(p, int(s)) for p, s, _ in planned] == list(product(POLICIES, SEEDS))
    assert all(rest.split() == ["scale=paper"] for _, _, rest in planned)
    assert "21 runs into runs/paper_sim/ with launcher 'local'" in paper_plan
    command = paper_plan.split("command: ", 1)[1]
    assert f"policy={','.join(POLICIES)}" in command and "seed=0,1,2" in command
    assert "runs_root=runs/paper_sim" in command and "hydra/launcher=local" in command


def test_dry_run_paper_cost(paper_plan: str) -> None:
    train, evaluation = _per_run_steps(paper_plan)
    assert (train, evaluation) == _expected_steps("scale=paper")
    # the paper's protocol: 4 cells x 500 units x 3 episodes x 1000 steps
    assert evaluation == 4 * 500 * 3 * 1000
    assert train == 40000 * 4096 * compose(["scale=paper"]).algo.num_steps_per_env


def test_dry_run_overrides_change_the_cost(paper_plan: str) -> None:
    out = _dry_run("--dry-run", str(PAPER_SIM), "scale=smoke", "runs_root=/tmp/elsewhere")
    smoke = _per_run_steps(out)
    assert smoke == _expected_steps("scale=smoke")
    assert smoke[0] < _per_run_steps(paper_plan)[0] and smoke[1] < _per_run_steps(paper_plan)[1]
    assert "21 runs into /tmp/elsewhere/ with launcher 'local'" in out
    assert out.count("scale=smoke") >= 21  # every planned run carries the override
    assert "runs_root=/tmp/elsewhere" in out.split("command: ", 1)[1]


def test_dry_run_on_a_cluster_takes_the_command_line_launcher() -> None:
    out = _dry_run("--dry-run", str(PAPER_SIM), "hydra/launcher=slurm")
    assert "21 runs into runs/paper_sim/ with launcher 'slurm'" in out
    command = out.split("command: ", 1)[1]
    assert "hydra/launcher=slurm" in command and "hydra/launcher=local" not in command


def test_dry_run_documented_argument_order() -> None:
    out = run_python("-m", "lca.experiment", str(PAPER_SIM), "--dry-run", "scale=smoke", cwd=REPO)
    assert out.returncode == 0, out.stderr
    assert _per_run_steps(out.stdout) == _expected_steps("scale=smoke")


def test_dry_run_hours_from_the_measured_rates(paper_plan: str) -> None:
    """Worked by hand: 40 000 iterations x 24 steps x 4096 envs of training and 4 cells x 500
    units x 3 episodes x 1000 steps of evaluation, at the rates the benchmarks stored."""
    bench = REPO / "reports" / "bench"
    train_rate = json.loads((bench / "train.json").read_text())["steps_per_s"]
    eval_rate = max(
        r["steps_per_s"] for r in json.loads((bench / "env.json").read_text())["batched"]
    )
    hours = (3_932_160_000 / train_rate + 6_000_000 / eval_rate) / 3600
    assert f"estimated cost: {hours:.2f} h per run, {21 * hours:.1f} core-pair hours" in paper_plan


def test_cost_estimate_reads_the_chosen_backends_rates(tmp_path, monkeypatch) -> None:
    pytest.importorskip("mujoco_warp", reason="the gpu extra")
    monkeypatch.setattr(experiment, "BENCH_DIR", tmp_path)
    smoke = ["scale=smoke", "sim.backend=warp"]
    assert "seconds" not in experiment.estimate_seconds(smoke)  # not measured: no guess
    (tmp_path / "train_warp.json").write_text(json.dumps({"steps_per_s": 100.0}))
    rows = [{"steps_per_s": 50.0}, {"steps_per_s": 200.0}]
    (tmp_path / "env_warp.json").write_text(json.dumps({"batched": rows}))
    (tmp_path / "train.json").write_text(json.dumps({"steps_per_s": 1.0}))  # mjbatch's: unused
    cost = experiment.estimate_seconds(smoke)
    expected = cost["train_env_steps"] / 100.0 + cost["eval_env_steps"] / 200.0
    assert cost["backend"] == "warp" and cost["seconds"] == pytest.approx(expected)


def test_hardware_experiment_plan() -> None:
    out = _dry_run(str(REPO / "experiments" / "paper_hardware.yaml"), "--dry-run")
    planned = re.findall(r"^  policy=(\w+) seed=(\d+)", out, flags=re.M)
    assert planned == [("blind", "0"), ("one_mlp", "0"), ("two_cnn", "0"), ("two_mlp", "0")]
    assert "4 runs into runs/paper_sim/" in out  # shares the simulation table's trained runs
    assert "then: `python -m lca.hardware` on each run" in out


def test_dry_run_costs_a_policy_at_its_shipped_runs_rate(tmp_path, capsys) -> None:
    """A policy with a shipped seed is costed at that run's own training rate (the CNN pair
    trains ~4x slower than the benchmark's MLP), the others at the benchmark's."""
    import shutil

    source = REPO / "assets" / "policies" / "one_cnn"
    folder = tmp_path / "shipped" / "one_cnn"
    folder.mkdir(parents=True)
    for name in ("COMPLETE", "config.yaml", "train_curve.csv"):
        shutil.copy(source / name, folder / name)
    spec = {
        "name": "costs",
        "policies": ["blind", "one_cnn"],
        "seeds": [0, 1],
        "overrides": ["scale=reference"],
        "shipped": str(tmp_path / "shipped"),
    }
    (tmp_path / "costs.yaml").write_text(OmegaConf.to_yaml(spec))
    assert experiment.main([str(tmp_path / "costs.yaml"), "--dry-run"]) == 0
    out = capsys.readouterr().out
    planned = re.findall(r"^  policy=(\w+) seed=(\d+)", out, flags=re.M)
    assert planned == [("blind", "0"), ("blind", "1"), ("one_cnn", "1")]

    import pandas as pd

    last = pd.read_csv(folder / "train_curve.csv").iloc[-1]
    cnn_rate = last["env_steps"] / round(float(last["wall_s"]), 1)
    bench_rate = json.loads((REPO / "reports" / "bench" / "train.json").read_text())["steps_per_s"]
    eval_rate = max(
        r["steps_per_s"]
        for r in json.loads((REPO / "reports" / "bench" / "env.json").read_text())["batched"]
    )
    train, evaluation = _expected_steps("scale=reference")
    cnn_h = (train / cnn_rate + evaluation / eval_rate) / 3600
    blind_h = (train / bench_rate + evaluation / eval_rate) / 3600
    assert cnn_h > 2 * blind_h  # what the single benchmark rate hid
    assert (
        f"estimated cost: {(2 * blind_h + cnn_h):.1f} core-pair hours in all; per run: "
        f"blind {blind_h:.2f} h ({bench_rate:,.0f} steps/s, `python -m lca.bench train`), "
        f"one_cnn {cnn_h:.2f} h ({cnn_rate:,.0f} steps/s, its shipped runs)"
    ) in out
