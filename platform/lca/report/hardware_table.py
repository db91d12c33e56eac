"""The paper's hardware table: success x/N and precision ("Track (m)") per task, LaTeX and
CSV. Precision is the paper's: the mean absolute deviation of the net lateral drift across
the successful trials (one success gives 0.000; none gives "--")."""

from __future__ import annotations

import numpy as np
import pandas as pd

from lca.report.collect import row_key

TASK_TITLES = {
    "stair_ascent": "Stair Ascent",
    "stair_descent": "Stair Descent",
    "hinged_ledge": "Hinged Ledge",
    "soft_ledge": "Soft Ledge",
}
HARDWARE_ROWS = ["Blind", "One-Stage MLP", "Two-Stage CNN", "Two-Stage MLP"]
SUCCESS = "$R_{\\mathrm{succ}}$ (\\%, $\\uparrow$)"
TRACK = "Track (m, $\\downarrow$)"


def mean_absolute_deviation(values: pd.Series) -> float:
    """Mean |x - mean(x)|; NaN for no values."""
    values = values.astype(float)
    return float((values - values.mean()).abs().mean()) if len(values) else np.nan


def hardware_rows(trials: pd.DataFrame) -> pd.DataFrame:
    """Per task: successes, trials, precision (MAD of the drift) and the mean |drift|, over
    successful trials."""
    rows = []
    for task, t in trials.groupby("task", sort=False):
        ok = t[t.success.astype(bool)]
        rows.append(
            {
                "task": task,
                "successes": int(len(ok)),
                "trials": int(len(t)),
                "track_mad_m": mean_absolute_deviation(ok.drift_m),
                "mean_abs_drift_m": float(ok.drift_m.abs().mean()) if len(ok) else np.nan,
            }
        )
    return pd.DataFrame(rows)


def hardware_table(per_policy: dict[str, pd.DataFrame]) -> tuple[pd.DataFrame, str]:
    """(long CSV table, LaTeX) from {policy label: trials}."""
    long = []
    for label, trials in per_policy.items():
        for row in hardware_rows(trials).itertuples():
            long.append({"policy": label, **row._asdict()})
    table = pd.DataFrame(long).drop(columns="Index", errors="ignore")
    if table.empty:
        return table, ""
    policies = sorted(
        table.policy.unique(),
        key=lambda p: (
            HARDWARE_ROWS.index(p) if p in HARDWARE_ROWS else len(HARDWARE_ROWS),
            row_key(p),
        ),
    )
    tasks = [t for t in TASK_TITLES if t in set(table.task)]
    columns = pd.MultiIndex.from_product([[TASK_TITLES[t] for t in tasks], [SUCCESS, TRACK]])
    text = pd.DataFrame("--", index=policies, columns=columns)
    for r in table.itertuples():
        text.loc[r.policy, (TASK_TITLES[r.task], SUCCESS)] = f"{r.successes}/{r.trials}"
        if not np.isnan(r.track_mad_m):
            text.loc[r.policy, (TASK_TITLES[r.task], TRACK)] = f"{r.track_mad_m:.3f}"
    latex = text.style.to_latex(
        hrules=True,
        multicol_align="c",
        column_format="l" + "c" * text.shape[1],
        caption="Four tasks in simulation. Success rate ($\\uparrow$) and precision in m "
        "($\\downarrow$): the mean absolute deviation of the net lateral drift across the "
        "successful trials.",
        label="tab:tasks_all",
        position="t",
    )
    return table, latex
