"""Reference rows: shipped policies (`assets/policies/<name>/`) evaluated on a run's own
cells, seeds and sizes, so that a newcomer's first table has rows that walk beside theirs.

Each evaluation is cached under `<runs_root>/.reference/<name>-<key>/`, the key a hash of the
evaluation settings and the policy's checkpoint: every later run with the same settings
reuses it. The cached run's rows read "<label> (reference: <name>)", never pooled with a new
run's (two shipped policies of one label, e.g. the flat and the terrain blind walkers, stay two
rows).
"""

from __future__ import annotations

import contextlib
import fcntl
import hashlib
import json
import shutil
from pathlib import Path

from omegaconf import DictConfig, OmegaConf

from lca.evaluate.policy import final_checkpoint
from lca.evaluate.protocol import PROTOCOL_VERSION
from lca.evaluate.run import evaluate_and_write
from lca.paths import assets_dir
from lca.store import COMPLETE, PROVENANCE

MARK = " (reference: {name})"
# what a reference run carries over from the shipped one: no exports, clips or results
KEEP = ("config.yaml", PROVENANCE, "train_cfg.json", "train_curve.csv", COMPLETE)
NO_MEDIA = {"videos": False, "reference": []}


def reference_runs(cfg: DictConfig, log=print) -> list[Path]:
    """The cached, evaluated copy of every policy in `cfg.eval.reference`, evaluated like
    `cfg`'s own run (its eval settings, clips off)."""
    cache = Path(cfg.runs_root) / ".reference"
    return [reference_run(name, cfg.eval, cache, log) for name in cfg.eval.reference]


def reference_run(name: str, eval_cfg: DictConfig, cache: Path, log=print) -> Path:
    shipped = assets_dir() / "policies" / name  # eval.reference is checked at composition
    settings = OmegaConf.to_container(eval_cfg, resolve=True)
    settings = {k: v for k, v in settings.items() if k not in ("videos", "reference")}
    settings["protocol_version"] = PROTOCOL_VERSION  # a newer protocol evaluates afresh
    checkpoint = final_checkpoint(shipped)
    digest = hashlib.sha256(json.dumps(settings, sort_keys=True).encode())
    digest.update(checkpoint.read_bytes())
    run = cache / f"{name}-{digest.hexdigest()[:12]}"
    cache.mkdir(parents=True, exist_ok=True)
    with _locked(cache / f"{name}.lock"):  # parallel sweep jobs evaluate it once
        if not (run / "summary.csv").is_file():
            _copy(shipped, run, checkpoint, eval_cfg, name)
            log(f"[lca] reference {name}: evaluating on this run's cells (cached in {run})")
            evaluate_and_write(run, log=log)
    return run


def _copy(shipped: Path, run: Path, checkpoint: Path, eval_cfg: DictConfig, name: str) -> None:
    copy_run(shipped, run, checkpoint, eval=OmegaConf.merge(eval_cfg, NO_MEDIA))
    cfg = OmegaConf.load(run / "config.yaml")
    cfg.policy.label = cfg.policy.label + MARK.format(name=name)
    OmegaConf.save(cfg, run / "config.yaml")


def copy_run(shipped: Path, run: Path, checkpoint: Path, **settings) -> None:
    """A fresh run directory `run` holding `shipped`'s files of KEEP and `checkpoint`, each
    top-level config group of `settings` merged into its config."""
    shutil.rmtree(run, ignore_errors=True)
    (run / "checkpoints").mkdir(parents=True)
    for name in KEEP:
        if (shipped / name).exists():
            shutil.copy2(shipped / name, run / name)
    shutil.copy2(checkpoint, run / "checkpoints" / checkpoint.name)
    cfg = OmegaConf.load(run / "config.yaml")
    for key, value in settings.items():
        cfg[key] = OmegaConf.merge(cfg[key], value)
    OmegaConf.save(cfg, run / "config.yaml")


@contextlib.contextmanager
def _locked(path: Path):
    with path.open("w") as handle:
        fcntl.flock(handle, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(handle, fcntl.LOCK_UN)
