"""The training-reward figure: one line per policy (mean over seeds) with a shaded band."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import pandas as pd  # noqa: E402

from lca.report.collect import RunRecord, row_key  # noqa: E402

SMOOTH = 5  # iterations of rolling mean


def reward_curves(runs: list[RunRecord]) -> dict[str, pd.DataFrame]:
    """Per policy: iteration-indexed mean and band (min..max over seeds; +-1 rolling std for
    a single seed)."""
    out = {}
    labels = sorted({r.label for r in runs if r.curve is not None}, key=row_key)
    for label in labels:
        curves = [
            r.curve.set_index("iteration")["mean_reward"].rolling(SMOOTH, min_periods=1).mean()
            for r in runs
            if r.label == label and r.curve is not None
        ]
        stacked = pd.concat(curves, axis=1)
        mean = stacked.mean(axis=1)
        if stacked.shape[1] > 1:
            low, high = stacked.min(axis=1), stacked.max(axis=1)
        else:
            std = stacked.iloc[:, 0].rolling(SMOOTH, min_periods=1).std().fillna(0.0)
            low, high = mean - std, mean + std
        out[label] = pd.DataFrame({"mean": mean, "low": low, "high": high})
    return out


def plot_rewards(runs: list[RunRecord], out_stem: Path) -> list[Path]:
    curves = reward_curves(runs)
    fig, ax = plt.subplots(figsize=(6.4, 3.8))
    for label, c in curves.items():
        (line,) = ax.plot(c.index, c["mean"], label=label, lw=1.6)
        ax.fill_between(c.index, c["low"], c["high"], color=line.get_color(), alpha=0.2, lw=0)
    ax.set_xlabel("iteration")
    ax.set_ylabel("mean episode return")
    ax.set_title("Training rewards")
    ax.grid(alpha=0.3)
    if curves and any(c["mean"].notna().any() for c in curves.values()):
        ax.legend(fontsize=8, frameon=False)
    else:  # e.g. a few smoke iterations: no episode ended, so there is no return to plot
        ax.text(
            0.5,
            0.5,
            "no finished episode yet:\nno episode return to plot",
            transform=ax.transAxes,
            ha="center",
            va="center",
            fontsize=11,
            color="0.4",
        )
    fig.tight_layout()
    paths = [out_stem.with_suffix(".png"), out_stem.with_suffix(".pdf")]
    for path in paths:
        fig.savefig(path, dpi=150)
    plt.close(fig)
    return paths
