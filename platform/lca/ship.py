"""Copy a trained run directory into the repository, small: `assets/policies/<name>/`.

    python -m lca.ship <run_dir> <dest> [--resumable]

Kept: config.yaml, provenance.json, train_cfg.json, train_curve.csv, the in-training
evaluations, summary.csv and results.parquet (when evaluated), exported/ (ONNX +
TorchScript) and the final checkpoint without its optimizer state (evaluation and export
need only the networks).
`--resumable` ships `checkpoints/latest.pt` instead, so an unfinished training can be
resumed by a later session (`cp -r dest runs/...` and re-run the same command): networks
only by default (the resumed run continues from that iteration with a fresh Adam at the run's
adapted learning rate and a fresh environment, which perturbs a fragile gait for a while),
whole with `--exact` (bit for bit, about 4x larger).
"""

from __future__ import annotations

import argparse
import shutil
import sys
from pathlib import Path

import pandas as pd
import torch

CURVE = "train_curve.csv"
FILES = (
    "config.yaml",
    "provenance.json",
    "train_cfg.json",
    CURVE,
    "probe_evals.csv",
    "summary.csv",
    "results.parquet",
    "COMPLETE",
)
DROPPED_KEYS = ("optimizer_state_dict", "lca_loop_state")


def slim_checkpoint(src: Path, dest: Path) -> None:
    """`src` without the optimizer state and the training loop's state (env, RNG): what
    evaluation and export need."""
    state = torch.load(src, map_location="cpu", weights_only=False)
    optimizer = state.get("optimizer_state_dict")
    if optimizer:  # the adapted rate: a resume from this file restarts Adam at it
        state.setdefault("infos", {})["learning_rate"] = optimizer["param_groups"][0]["lr"]
    for key in DROPPED_KEYS:
        state.pop(key, None)
    dest.parent.mkdir(parents=True, exist_ok=True)
    torch.save(state, dest)


def ship(run_dir: Path, dest: Path, resumable: bool = False, exact: bool = False) -> list[Path]:
    run_dir, dest = Path(run_dir), Path(dest)
    if not (run_dir / "config.yaml").exists():
        raise FileNotFoundError(f"{run_dir} has no config.yaml: not a run directory")
    shutil.rmtree(dest, ignore_errors=True)
    dest.mkdir(parents=True)
    for name in FILES:
        if name == CURVE and (run_dir / name).exists():
            # a long run logs ~300 bytes an iteration at full float precision; 6 digits halve it
            pd.read_csv(run_dir / name).to_csv(
                dest / name, index=False, float_format="%.6g", na_rep="nan"
            )
        elif (run_dir / name).exists():
            shutil.copy2(run_dir / name, dest / name)
    if (run_dir / "exported").exists():
        shutil.copytree(run_dir / "exported", dest / "exported")
    checkpoints = run_dir / "checkpoints"
    if resumable and exact:
        shutil.copy2(checkpoints / "latest.pt", _mkdir(dest / "checkpoints") / "latest.pt")
    elif resumable:
        slim_checkpoint(checkpoints / "latest.pt", dest / "checkpoints" / "latest.pt")
    else:
        finals = sorted(checkpoints.glob("final_*.pt"))
        if not finals:
            raise FileNotFoundError(f"{checkpoints} has no final_*.pt (or ship --resumable)")
        slim_checkpoint(finals[-1], dest / "checkpoints" / finals[-1].name)
    return sorted(p for p in dest.rglob("*") if p.is_file())


def _mkdir(path: Path) -> Path:
    path.mkdir(parents=True, exist_ok=True)
    return path


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m lca.ship")
    parser.add_argument("run_dir", type=Path)
    parser.add_argument("dest", type=Path)
    parser.add_argument("--resumable", action="store_true")
    parser.add_argument("--exact", action="store_true", help="with --resumable: latest.pt whole")
    args = parser.parse_args(argv)
    if args.exact and not args.resumable:
        parser.error("--exact needs --resumable")
    for path in ship(args.run_dir, args.dest, args.resumable, args.exact):
        print(f"{path.stat().st_size / 1e6:7.2f} MB  {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
