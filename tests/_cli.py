"""What every test layer shares: repository paths, the quiet one-thread smoke overrides, and
the subprocess runner for entry points (`python run.py`, `python -m lca.<stage>`)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
RUN_PY = REPO / "run.py"
CONF = REPO / "conf"
# The smoke scale, quiet and on one thread (torch and mjbatch).
SMOKE = ["scale=smoke", "logger=none", "torch_threads=1", "sim.num_threads=1"]


def cli_env() -> dict[str, str]:
    """The test process's environment without wandb or Hydra settings, output unbuffered."""
    env = {k: v for k, v in os.environ.items() if not k.startswith(("WANDB_", "HYDRA_"))}
    env["PYTHONUNBUFFERED"] = "1"
    return env


def run_python(
    *args: str, cwd: Path, timeout: float = 120, env: dict[str, str] | None = None
) -> subprocess.CompletedProcess:
    """`python ARGS` from `cwd`, output captured (MuJoCo may drop a MUJOCO_LOG.TXT there), in
    `env` (default: `cli_env()`)."""
    return subprocess.run(
        [sys.executable, *args],
        cwd=cwd,
        env=cli_env() if env is None else env,
        capture_output=True,
        text=True,
        timeout=timeout,
        check=False,
    )


def run_module(
    *args: str, cwd: Path, timeout: float = 120, env: dict[str, str] | None = None
) -> subprocess.CompletedProcess:
    """`python -m ARGS` from `cwd`."""
    return run_python("-m", *args, cwd=cwd, timeout=timeout, env=env)


def run_cli(
    *args: str, cwd: Path, timeout: float = 120, env: dict[str, str] | None = None
) -> subprocess.CompletedProcess:
    """`python run.py ARGS` from `cwd`."""
    return run_python(str(RUN_PY), *args, cwd=cwd, timeout=timeout, env=env)
