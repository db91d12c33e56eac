"""The paper's hardware table: success x/N and drift (m) per task, LaTeX and CSV."""

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


def hardware_rows(trials: pd.DataFrame) -> pd.DataFrame:
    """Per task: successes, trials, mean drift over successful trials."""
    rows = []
    for task, t in trials.groupby("task", sort=False):
        ok = t[t.success.astype(bool)]
        rows.append(
            {
                "task": task,
                "successes": int(len(ok)),
                "trials": int(len(t)),
                "drift_m": float(ok.drift_m.mean()) if len(ok) else np.nan,
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
    columns = pd.MultiIndex.from_product(
        [[TASK_TITLES[t] for t in tasks], ["$R_{\\mathrm{succ}}$", "Drift (m, $\\downarrow$)"]]
    )
    text = pd.DataFrame("--", index=policies, columns=columns)
    for r in table.itertuples():
        text.loc[r.policy, (TASK_TITLES[r.task], "$R_{\\mathrm{succ}}$")] = (
            f"{r.successes}/{r.trials}"
        )
        if not np.isnan(r.drift_m):
            text.loc[r.policy, (TASK_TITLES[r.task], "Drift (m, $\\downarrow$)")] = (
                f"{r.drift_m:.3f}"
            )
    latex = text.style.to_latex(
        hrules=True,
        multicol_align="c",
        column_format="l" + "c" * text.shape[1],
        caption="Four tasks in simulation. Success ($\\uparrow$) and lateral drift in m "
        "($\\downarrow$), mean over successful trials.",
        label="tab:tasks_all",
        position="t",
    )
    return table, latex
