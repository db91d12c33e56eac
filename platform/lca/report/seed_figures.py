"""Pictures of training seeds: per cell, each policy's per-seed values beside its IQM and CI;
and performance profiles of success over units pooled across seeds (rliable's plots)."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

from lca.evaluate.metrics import CELL_KEYS, unit_values  # noqa: E402
from lca.report.collect import row_key  # noqa: E402
from lca.report.seeds import performance_profile  # noqa: E402

TITLES = {
    "success": "success (%)",
    "contacts_per_step": "contacts / step (%)",
    "track_cm_s": "tracking error (cm/s)",
}


def seed_figures(table: pd.DataFrame, out_dir: Path) -> list[Path]:
    """`seeds_<terrain>-<difficulty>.png`: one panel per metric, a column per policy."""
    paths = []
    seed_columns = [c for c in table.columns if c.startswith("seed_")]
    for (terrain, difficulty), cell in table.groupby(["terrain", "difficulty"], sort=False):
        fig, axes = plt.subplots(1, len(TITLES), figsize=(4.2 * len(TITLES), 3.4))
        policies = sorted(cell["policy"].unique(), key=row_key)
        for ax, (metric, title) in zip(axes, TITLES.items(), strict=True):
            rows = cell[cell.metric == metric].set_index("policy")
            for i, policy in enumerate(policies):
                row = rows.loc[policy]
                seeds = row[seed_columns].dropna().to_numpy(float)
                jitter = np.linspace(-0.12, 0.12, len(seeds)) if len(seeds) > 1 else [0.0]
                ax.scatter(i + np.asarray(jitter), seeds, s=18, color="0.45", zorder=2)
                if row["n_seeds"] > 1:
                    low, high = row["iqm_ci_low"], row["iqm_ci_high"]
                    err = [[row["iqm"] - low], [high - row["iqm"]]]
                    ax.errorbar(i + 0.3, row["iqm"], yerr=err, fmt="D", color="tab:blue")
            ax.set_xticks(range(len(policies)), policies, rotation=30, ha="right", fontsize=8)
            ax.set_title(title, fontsize=10)
            ax.grid(alpha=0.3, axis="y")
        fig.suptitle(
            f"{terrain}, {difficulty}: each training seed (grey), IQM across seeds with its "
            "95 % stratified bootstrap CI (blue)",
            fontsize=10,
        )
        fig.tight_layout()
        path = out_dir / f"seeds_{terrain}-{difficulty}.png"
        fig.savefig(path, dpi=110)
        plt.close(fig)
        paths.append(path)
    return paths


def profile_figure(episodes: pd.DataFrame, path: Path) -> Path:
    """Per cell: the fraction of units (all seeds pooled) whose success exceeds tau."""
    cells = list(episodes.groupby(CELL_KEYS, sort=False).groups)
    fig, axes = plt.subplots(1, len(cells), figsize=(3.6 * len(cells), 3.2), squeeze=False)
    taus = np.linspace(0, 100, 101)
    for ax, (terrain, difficulty) in zip(axes[0], cells, strict=True):
        cell = episodes[
            (episodes.cell_terrain == terrain) & (episodes.cell_difficulty == difficulty)
        ]
        for policy in sorted(cell["policy"].unique(), key=row_key):
            units = unit_values(cell[cell.policy == policy], "success").to_numpy(float)
            ax.plot(taus, performance_profile(units, taus), label=policy, lw=1.4)
        ax.set_title(f"{terrain}, {difficulty}", fontsize=10)
        ax.set_xlabel("success threshold tau (%)")
        ax.set_ylim(-0.02, 1.02)
        ax.grid(alpha=0.3)
    axes[0][0].set_ylabel("fraction of units > tau")
    axes[0][-1].legend(fontsize=7, frameon=False)
    fig.suptitle("Performance profiles: success over units, seeds pooled", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path
