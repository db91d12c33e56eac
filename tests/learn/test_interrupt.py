"""SIGINT/SIGTERM stop a training after the iteration in progress, with that iteration saved:
an interrupted run loses nothing (`lca.learn.interrupt`)."""

from __future__ import annotations

import signal
import subprocess
import time

import pytest
import torch

from lca.learn.interrupt import StopOnSignal
from lca.store import COMPLETE, FAILED, RunDir

from .helpers import cli_command, cli_env, read_curve

# no periodic checkpoint: the one on disk after the signal is the signal's
LONG_RUN = ("scale=smoke", "scale.max_iterations=400", "scale.checkpoint_interval=1000")


def test_first_signal_is_noted_second_acts_as_before() -> None:
    saved = signal.signal(signal.SIGINT, signal.default_int_handler)  # Python's own Ctrl-C
    sigterm = signal.getsignal(signal.SIGTERM)
    try:
        with StopOnSignal() as stop:
            signal.raise_signal(signal.SIGTERM)
            assert stop.signum == signal.SIGTERM  # noted, the process goes on
            with pytest.raises(KeyboardInterrupt):
                signal.raise_signal(signal.SIGINT)  # the second acts at once
        assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
        assert signal.getsignal(signal.SIGTERM) is sigterm
    finally:
        signal.signal(signal.SIGINT, saved)


@pytest.mark.slow
@pytest.mark.e2e
def test_sigterm_saves_the_iteration_in_progress(tmp_path) -> None:
    """SIGTERM between checkpoints: the run exits with 143 after the iteration it was in,
    `latest.pt` holds that iteration (the curve's last row), and the run is neither complete
    nor failed, its lock free: the same command resumes it with nothing lost."""
    runs_root = tmp_path / "runs"
    args = [*LONG_RUN, "logger=none", "torch_threads=1", f"runs_root={runs_root}"]
    proc = subprocess.Popen(
        cli_command(*args), cwd=tmp_path, env=cli_env(), stdout=subprocess.PIPE, text=True
    )
    deadline = time.monotonic() + 240
    curves = []
    while not (curves and len(read_curve(curves[0])) >= 3):
        assert proc.poll() is None and time.monotonic() < deadline, "no training to stop"
        time.sleep(0.2)
        curves = list(runs_root.rglob("train_curve.csv"))
    run = curves[0].parent
    proc.send_signal(signal.SIGTERM)
    out, _ = proc.communicate(timeout=120)
    curve = run / "train_curve.csv"
    assert proc.returncode == 128 + signal.SIGTERM, out[-3000:]
    assert "SIGTERM: stopping after this iteration" in out
    last = int(read_curve(curve)[-1]["iteration"])
    assert f"training stopped after iteration {last}, saved in" in out
    assert 2 <= last < 399
    saved = torch.load(run / "checkpoints" / "latest.pt", weights_only=False, map_location="cpu")
    assert saved["iter"] == last, out[-3000:]
    assert not (run / COMPLETE).exists() and not (run / FAILED).exists()
    with RunDir(run).lock():  # released, not left to be taken over
        pass
