"""Runs you can trust: one owner per run directory, atomic rewrites, readable checkpoints or
a clear way out, and loud failures instead of a COMPLETE marker."""

from __future__ import annotations

import csv
import os
import signal
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import torch

from lca.learn.trainer import CURVE_FIELDS
from lca.store import RunDir, RunLockedError, atomic_write, write_atomically

from .helpers import make_trainer, read_curve, smoke_cfg

pytestmark = pytest.mark.slow  # trains, evaluates or runs a stage: see README

HOLD = (
    "import sys, time; from lca.store import RunDir\n"
    "with RunDir(sys.argv[1]).lock():\n"
    "    print('locked', flush=True); time.sleep(60)\n"
)


def _holder(path):
    proc = subprocess.Popen([sys.executable, "-c", HOLD, str(path)], stdout=subprocess.PIPE)
    assert proc.stdout.readline().strip() == b"locked"
    return proc


def test_a_second_owner_is_refused_naming_the_first(tmp_path):
    proc = _holder(tmp_path / "run")
    try:
        with (
            pytest.raises(RunLockedError, match=rf"in use by PID {proc.pid} on "),
            RunDir(tmp_path / "run").lock(),
        ):
            pass
    finally:
        proc.kill()
        proc.wait()


def test_a_killed_owners_lock_is_taken_over(tmp_path, capsys):
    proc = _holder(tmp_path / "run")
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait()
    with RunDir(tmp_path / "run").lock():
        assert f"taking over the lock left by PID {proc.pid}" in capsys.readouterr().out
    with RunDir(tmp_path / "run").lock():  # released cleanly: nothing to take over
        assert "taking over" not in capsys.readouterr().out


def test_the_lock_is_reentrant_in_one_process(tmp_path):
    run = RunDir(tmp_path / "run")
    with run.lock(), run.lock():
        pass
    with run.lock():
        pass


def test_curve_rewrite_interrupted_keeps_the_old_curve(tmp_path, smoke_scene, monkeypatch):
    trainer = make_trainer(smoke_cfg("scale.max_iterations=2"), tmp_path / "run", smoke_scene)
    trainer.train()
    before = trainer.run.curve.read_text()

    def boom(self, rows):
        raise KeyboardInterrupt("killed mid-rewrite")

    monkeypatch.setattr(csv.DictWriter, "writerows", boom)
    with pytest.raises(KeyboardInterrupt):
        trainer._rewrite_curve(read_curve(trainer.run.curve))
    assert trainer.run.curve.read_text() == before
    assert not [p for p in trainer.run.path.iterdir() if p.name.startswith(".train_curve")]


def _truncate(path):
    data = path.read_bytes()
    path.write_bytes(data[: len(data) // 3])


class _Crash(Exception):
    pass


def _crash_after(iteration: int):
    def hook(trainer, it, row):
        if it == iteration:
            raise _Crash(f"crashed after iteration {it}")
        return False

    return hook


def test_truncated_latest_falls_back_to_previous(tmp_path, smoke_scene, capsys):
    cfg = smoke_cfg("scale.max_iterations=4", "scale.checkpoint_interval=1")
    first = make_trainer(cfg, tmp_path / "run", smoke_scene)
    with pytest.raises(_Crash):  # latest: it 2, previous: it 1
        first.train(hook=_crash_after(2))
    _truncate(first.run.checkpoints / "latest.pt")
    capsys.readouterr()
    resumed = make_trainer(cfg, tmp_path / "run", smoke_scene)
    out = capsys.readouterr().out
    assert "skipping unreadable checkpoint" in out and "latest.pt" in out
    assert "(from previous.pt)" in out
    assert resumed.start == 2


def test_no_readable_checkpoint_names_the_files_and_the_way_out(tmp_path, smoke_scene):
    cfg = smoke_cfg("scale.max_iterations=3", "scale.checkpoint_interval=1")
    first = make_trainer(cfg, tmp_path / "run", smoke_scene)
    first.train(hook=lambda trainer, it, row: it == 1)
    for name in ("latest.pt", "previous.pt"):
        _truncate(first.run.checkpoints / name)
    with pytest.raises(RuntimeError) as err:
        make_trainer(cfg, tmp_path / "run", smoke_scene)
    message = str(err.value)
    assert "latest.pt" in message and "previous.pt" in message and "force=true" in message


def test_nan_actions_are_counted_zeroed_and_reset(smoke_scene):
    from lca.task.env import LocomotionEnv

    env = LocomotionEnv(smoke_cfg(), scene=smoke_scene)
    actions = torch.zeros(env.num_envs, env.num_actions)
    actions[1, 3] = float("nan")
    actions[2, 0] = float("inf")
    obs, rewards, dones, extras = env.step(actions)
    assert env.nonfinite_actions == 2
    assert extras["metrics"]["nonfinite_action"].tolist()[:3] == [False, True, True]
    assert dones[1] and dones[2] and not dones[0]
    assert np.isfinite(env.action).all() and (env.action[1:3] == 0).all()  # reset rows
    assert all(torch.isfinite(v).all() for v in obs.values())
    assert torch.isfinite(rewards).all()
    assert extras["log"]["Episode_Termination/nonfinite_actions_total"] == 2.0


def test_a_policy_with_no_finite_output_fails_loudly(tmp_path, smoke_scene):
    trainer = make_trainer(smoke_cfg(), tmp_path / "run", smoke_scene)
    steps = 8 * trainer.env.num_envs
    with pytest.raises(RuntimeError, match="every action of the policy was NaN"):
        trainer._check_finite(np.array([0, 0, 0, steps]), steps, 0, 0)


def test_an_exploding_simulation_fails_instead_of_completing(tmp_path, smoke_scene):
    trainer = make_trainer(smoke_cfg("scale.max_iterations=5"), tmp_path / "run", smoke_scene)
    streak = 0
    with pytest.raises(RuntimeError, match="every episode ended in a non-finite"):
        for it in range(5):
            streak = trainer._check_finite(np.array([8, 0, 8, 0]), 64, it, streak)
    assert trainer._check_finite(np.array([8, 2, 6, 0]), 64, 0, 2) == 0  # one healthy ending


def test_curve_holds_the_failure_counters(tmp_path, smoke_scene):
    trainer = make_trainer(smoke_cfg(), tmp_path / "run", smoke_scene)
    trainer.train()
    rows = read_curve(trainer.run.curve)
    for key in ("falls", "nonfinite", "nonfinite_actions"):
        assert key in CURVE_FIELDS and all(int(r[key]) >= 0 for r in rows)


def test_checkpoint_temporaries_are_unique_and_cleaned(tmp_path, smoke_scene):
    trainer = make_trainer(smoke_cfg(), tmp_path / "run", smoke_scene)
    trainer.train()
    names = [p.name for p in trainer.run.checkpoints.iterdir()]
    assert not [n for n in names if n.startswith(".") or n.endswith(".tmp")], names


def test_a_failed_atomic_write_keeps_the_old_file_and_leaves_nothing(tmp_path):
    target = tmp_path / "summary.csv"
    atomic_write(target, "old")

    def broken(tmp):
        Path(tmp).write_text("half")
        raise OSError("disk full")

    with pytest.raises(OSError, match="disk full"):
        write_atomically(target, broken)
    assert target.read_text() == "old" and sorted(tmp_path.iterdir()) == [target]
    write_atomically(target, lambda tmp: Path(tmp).write_text("new"), suffix=".csv")
    assert target.read_text() == "new" and sorted(tmp_path.iterdir()) == [target]
