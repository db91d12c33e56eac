"""The run directory: provenance, completion marker, curves and checkpoint paths.

Stages talk through these files, so any stage can be re-run alone.
"""

from __future__ import annotations

import contextlib
import fcntl
import json
import os
import platform
import shutil
import socket
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from importlib import metadata
from pathlib import Path

from omegaconf import DictConfig, OmegaConf

from lca.departures import departures
from lca.paths import root

LOCK = ".lock"
_HELD: dict[Path, int] = {}  # run directories this process has locked -> nesting depth
PACKAGES = ("lca", "torch", "mujoco", "mjbatch", "rsl-rl-lib", "hydra-core", "numpy", "tensordict")
COMPLETE = "COMPLETE"
TRAIN_CFG = "train_cfg.json"
FAILED = "FAILED"
PROVENANCE = "provenance.json"
# what `earlier_starts` keeps of each start before this one
START_KEYS = ("started", "argv", "git", "host", "platform", "cpu", "resumed")
KEEP_ON_FORCE = (".hydra", LOCK)  # Hydra writes .hydra/ before the job starts


def write_atomically(path: Path, write: Callable[[str], object], suffix: str = "") -> Path:
    """`write(tmp)` into a uniquely named temporary file beside `path` (ending in `suffix`,
    for writers that read the format from the name), then rename it to `path`: the file
    appears complete or not at all, and a failed write leaves nothing behind."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=suffix)
    os.close(fd)
    try:
        write(tmp)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    os.replace(tmp, path)
    return path


def atomic_write(path: Path, text: str) -> None:
    write_atomically(path, lambda tmp: Path(tmp).write_text(text))


def git_state(repo: Path) -> dict:
    def git(*args: str) -> str:
        out = subprocess.run(["git", *args], cwd=repo, capture_output=True, text=True, check=False)
        return out.stdout.strip()

    commit = git("rev-parse", "HEAD")
    return {
        "commit": commit or None,
        "dirty": bool(git("status", "--porcelain")) if commit else None,
    }


def cpu_model() -> str:
    """The CPU's model name, '' where unknown: machines of one kind differ in speed, so a
    wall-clock figure needs its machine."""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor()


def versions() -> dict:
    found = {}
    for name in PACKAGES:
        try:
            found[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            found[name] = None
    return found


class RunLockedError(RuntimeError):
    """Another live process owns the run directory."""


def _holder(fd: int) -> dict:
    os.lseek(fd, 0, os.SEEK_SET)
    text = os.read(fd, 4096).decode(errors="replace").strip()
    try:
        return json.loads(text) if text else {}
    except json.JSONDecodeError:
        return {"unreadable": text[:80]}


def _describe(holder: dict) -> str:
    if not holder:
        return "another process"
    return f"PID {holder.get('pid')} on {holder.get('host')} (since {holder.get('since')})"


class RunDir:
    def __init__(self, path: str | Path):
        self.path = Path(path)
        self.checkpoints = self.path / "checkpoints"
        self.exported = self.path / "exported"
        self.curve = self.path / "train_curve.csv"

    @contextlib.contextmanager
    def lock(self):
        """Own the run directory for the block: an advisory lock (`.lock`, holding the owner's
        PID and host). A second process fails at once with a message naming the owner; a lock
        left by a killed process is released by the kernel and taken over. Re-entrant within
        one process."""
        key = self.path.resolve()
        if _HELD.get(key):
            _HELD[key] += 1
            try:
                yield
            finally:
                _HELD[key] -= 1
            return
        self.path.mkdir(parents=True, exist_ok=True)
        fd = os.open(self.path / LOCK, os.O_RDWR | os.O_CREAT, 0o644)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = _holder(fd)
            os.close(fd)
            raise RunLockedError(
                f"{self.path} is in use by {_describe(holder)}; wait for it to finish or "
                f"stop that process (lock file: {self.path / LOCK})"
            ) from None
        stale = _holder(fd)
        if stale:
            print(f"[lca] {self.path}: taking over the lock left by {_describe(stale)}")
        me = {"pid": os.getpid(), "host": socket.gethostname(), "since": time.strftime("%c")}
        os.ftruncate(fd, 0)
        os.lseek(fd, 0, os.SEEK_SET)
        os.write(fd, json.dumps(me).encode())
        _HELD[key] = 1
        try:
            yield
        finally:
            del _HELD[key]
            os.ftruncate(fd, 0)  # an empty lock file: released cleanly
            fcntl.flock(fd, fcntl.LOCK_UN)
            os.close(fd)

    @property
    def complete(self) -> bool:
        return (self.path / COMPLETE).exists()

    def mark_complete(self, summary: dict) -> None:
        atomic_write(self.path / COMPLETE, json.dumps(summary, indent=2))

    def clear_complete(self) -> None:
        (self.path / COMPLETE).unlink(missing_ok=True)

    @property
    def failed(self) -> dict | None:
        """The reason recorded by the last run that failed here, if any."""
        path = self.path / FAILED
        return json.loads(path.read_text()) if path.exists() else None

    def mark_failed(self, error: BaseException) -> None:
        reason = {"error": type(error).__name__, "message": str(error)[:2000]}
        atomic_write(self.path / FAILED, json.dumps(reason | {"at": time.strftime("%c")}))

    def clear_outputs(self) -> None:
        """Delete every output of an earlier run (`force=true`): checkpoints, curves, exports,
        evaluations, results, reports and markers."""
        for entry in self.path.iterdir() if self.path.exists() else ():
            if entry.name in KEEP_ON_FORCE:
                continue
            if entry.is_dir() and not entry.is_symlink():
                shutil.rmtree(entry)
            else:
                entry.unlink()

    def write_provenance(self, cfg: DictConfig, overrides: list[str], choices: dict) -> None:
        """config.yaml and provenance.json of this start. A run started before (interrupted,
        resumed) keeps its earlier starts in `earlier_starts`, oldest first."""
        repo = root()
        atomic_write(self.path / "config.yaml", OmegaConf.to_yaml(cfg, resolve=True))
        previous = self.provenance()
        provenance = {
            "overrides": list(overrides),
            "choices": dict(choices),
            "seed": int(cfg.seed),
            "git": git_state(repo),
            "versions": versions(),
            "python": sys.version.split()[0],
            "platform": platform.platform(),
            "host": socket.gethostname(),
            "argv": sys.argv,
            "cpu": cpu_model(),
            "started": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
            "departures_from_paper": departures(cfg),
        }
        if previous:
            start = {key: previous[key] for key in START_KEYS if key in previous}
            provenance["earlier_starts"] = [*previous.get("earlier_starts", []), start]
        atomic_write(self.path / PROVENANCE, json.dumps(provenance, indent=2))

    def provenance(self) -> dict:
        """provenance.json ({} before the run's first start)."""
        path = self.path / PROVENANCE
        return json.loads(path.read_text()) if path.exists() else {}

    def record_resume(self, iteration: int, checkpoint: str, exact: bool) -> None:
        """Note in provenance.json that this start resumed at `iteration` from `checkpoint`,
        `exact` when the optimizer and the environments' state came with the networks (a
        shipped, networks-only checkpoint restarts both)."""
        provenance = self.provenance()
        if not provenance:  # a trainer built outside the pipeline (tests, benchmarks)
            return
        provenance["resumed"] = {"iteration": iteration, "from": checkpoint, "exact": exact}
        atomic_write(self.path / PROVENANCE, json.dumps(provenance, indent=2))

    def write_train_cfg(self, train_cfg: dict) -> None:
        """The rsl-rl runner config the run trains with: evaluation rebuilds the networks
        from it (class names resolved by rsl-rl) without the learning stage's code."""
        atomic_write(self.path / TRAIN_CFG, json.dumps(train_cfg, indent=2))

    def train_cfg(self) -> dict:
        path = self.path / TRAIN_CFG
        if not path.exists():
            raise FileNotFoundError(
                f"run_dir: {self.path} has no {TRAIN_CFG} (the networks to load); "
                "train it (or re-run it with force=true) first"
            )
        return json.loads(path.read_text())

    def latest_checkpoint(self) -> Path | None:
        path = self.checkpoints / "latest.pt"
        return path if path.exists() else None
