"""Learning evidence: train a blind MLP on flat ground at `scale=cpu` and show that episode
length and velocity tracking rise. Writes reports/learning_evidence.{png,md}.

    python -m lca.bench learn [overrides]   # e.g. scale.max_iterations=150
"""

from __future__ import annotations

import shutil
from collections.abc import Callable
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import pandas as pd  # noqa: E402

from lca.config import compose  # noqa: E402
from lca.learn.run import train_run  # noqa: E402
from lca.paths import reports_dir
from lca.store import RunDir  # noqa: E402

BASE = ["terrain=flat", "curriculum=blind", "actor=mlp", "encoder=mlp", "logger=none"]
REPORTS = reports_dir()


def _window(curve: pd.DataFrame, column: str, first: bool, frac: float = 0.1) -> float:
    n = max(1, int(len(curve) * frac))
    part = curve[column].dropna()
    part = part.head(n) if first else part.tail(n)
    return float(part.mean())


def plot(curve: pd.DataFrame, out: Path) -> None:
    fig, axes = plt.subplots(1, 3, figsize=(13, 3.6))
    x = curve["env_steps"] / 1e6
    for ax, col, label in zip(
        axes,
        ["mean_episode_length", "track_lin_vel_xy_exp", "mean_reward"],
        ["mean episode length (policy steps)", "track_lin_vel_xy_exp per episode", "mean return"],
        strict=True,
    ):
        ax.plot(x, curve[col], lw=1.2)
        ax.plot(x, curve[col].rolling(10, min_periods=1).mean(), lw=2)
        ax.set_xlabel("environment steps (M)")
        ax.set_title(label, fontsize=10)
        ax.grid(alpha=0.3)
    fig.suptitle("Blind MLP on flat ground, scale=cpu (256 envs)", fontsize=11)
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    plt.close(fig)


def run(overrides: list[str], log: Callable[[str], None] | None = print) -> dict:
    cfg = compose([*BASE, *overrides])
    run_path = Path(cfg.runs_root) / "learning_evidence"
    shutil.rmtree(run_path, ignore_errors=True)  # always a fresh run
    train_run(cfg, RunDir(run_path))
    return summarise(run_path, [*BASE, *overrides])


def summarise(run_path: Path, overrides: list[str]) -> dict:
    """Figure, markdown and numbers of a finished learning-evidence run."""
    curve = pd.read_csv(run_path / "train_curve.csv")
    REPORTS.mkdir(exist_ok=True)
    plot(curve, REPORTS / "learning_evidence.png")
    result = {
        "iterations": len(curve),
        "env_steps": int(curve["env_steps"].iloc[-1]),
        "wall_s": float(curve["wall_s"].iloc[-1]),
    }
    # the tracking kernel exp(-err^2 / 0.25) per policy step (sum / length / dt), in [0, 1]
    curve["tracking_per_step"] = curve.track_lin_vel_xy_exp / curve.mean_episode_length / 0.02
    for col in ("mean_episode_length", "track_lin_vel_xy_exp", "tracking_per_step", "mean_reward"):
        result[col] = {
            "first_10pct": _window(curve, col, True),
            "last_10pct": _window(curve, col, False),
        }
    write_markdown(result, overrides, REPORTS / "learning_evidence.md")
    return result


def write_markdown(r: dict, overrides: list[str], path: Path) -> None:
    rows = "\n".join(
        f"| `{col}` | {r[col]['first_10pct']:.2f} | {r[col]['last_10pct']:.2f} |"
        for col in (
            "mean_episode_length",
            "track_lin_vel_xy_exp",
            "tracking_per_step",
            "mean_reward",
        )
    )
    path.write_text(
        "# Learning evidence\n\n"
        f"`python -m lca.bench learn {' '.join(overrides[len(BASE) :])}` trains a blind MLP on "
        f"flat ground at `scale=cpu` ({' '.join(overrides)}): {r['iterations']} iterations, "
        f"{r['env_steps']:,} environment steps, {r['wall_s'] / 60:.1f} min on 2 CPU cores.\n\n"
        "Means over the first and the last 10 % of iterations. Episode length is in policy "
        "steps of 20 ms (episodes end at a fall or after 1000 steps); the tracking term is the "
        "weighted per-episode sum logged by the environment, and `tracking_per_step` the "
        "velocity-tracking kernel exp(-|v - u|^2 / 0.25) per step (1 = perfect). "
        "The mean return stays at the "
        "termination penalty (-4) because `only_positive_rewards` clips every step's other "
        "terms at zero until the policy's rewards outweigh its penalties.\n\n"
        "| quantity | first 10 % | last 10 % |\n|---|---:|---:|\n"
        f"{rows}\n\n![learning curves](learning_evidence.png)\n"
    )


def table(r: dict) -> str:
    lines = [f"{r['iterations']} iterations, {r['env_steps']:,} env steps, {r['wall_s']:.0f} s"]
    for col in ("mean_episode_length", "track_lin_vel_xy_exp", "tracking_per_step", "mean_reward"):
        a, b = r[col]["first_10pct"], r[col]["last_10pct"]
        lines.append(f"{col:>22}: first 10 % {a:8.2f} -> last 10 % {b:8.2f}")
    return "\n".join(lines)
