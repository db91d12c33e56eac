"""Builders shared by the report-layer tests.

`build_fixture_store` writes a small run store by hand: one folder per run with the
config.yaml a real run would hold (composed from `policy=<name> seed=<s>`), a
provenance.json, a train_curve.csv and a results.parquet of hand-made per-episode rows.
What goes in is declared in fixtures/runs.yaml (runs) and fixtures/cells.csv (per run and
cell: failed episodes, mean contacts/step and mean tracking error), so every number in the
report can be worked out by hand. Golden outputs live in golden/; regenerate them with
`LCA_UPDATE_GOLDEN=1 python -m pytest tests/report/test_golden.py` and inspect the diff.
"""

from __future__ import annotations

import html
import json
import os
import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from _cli import REPO, cli_env, run_python  # noqa: F401 (re-exported)
from omegaconf import OmegaConf

from lca.config import compose

HERE = Path(__file__).resolve().parent
FIXTURES = HERE / "fixtures"
GOLDEN = HERE / "golden"
UPDATE_GOLDEN = os.environ.get("LCA_UPDATE_GOLDEN") == "1"

# Per-unit offsets around a cell's mean (they sum to zero, so the unit mean of a cell is the
# value in cells.csv exactly) and per-episode offsets within a unit (also summing to zero).
CONTACT_UNIT = [-0.15, -0.05, 0.05, 0.15]
CONTACT_EPISODE = [-0.02, 0.02]
TRACK_UNIT = [-1.2, -0.4, 0.4, 1.2]
TRACK_EPISODE = [-0.1, 0.1]
CURVE_ITERATIONS = 20
NOT_A_RUN = "notes"  # a folder of the store that is not a run directory


def fixture_spec() -> dict:
    return OmegaConf.to_container(OmegaConf.load(FIXTURES / "runs.yaml"))


def fixture_cells() -> pd.DataFrame:
    return pd.read_csv(FIXTURES / "cells.csv")


def cell_episodes(failures: int, contacts: float, track: float, units: int, episodes: int):
    """Per-episode rows of one cell: the first `failures` rounds in (episode, unit) order fail,
    so failures spread over units before a unit fails twice."""
    rows = []
    order = [(e, u) for e in range(episodes) for u in range(units)]
    failed = set(order[:failures])
    for u in range(units):
        for e in range(episodes):
            ok = (e, u) not in failed
            rows.append(
                {
                    "unit": u,
                    "episode": e,
                    "success": 100.0 if ok else 0.0,
                    "steps": 1000 if ok else 400 + 100 * u,
                    "contacts_per_step": contacts + CONTACT_UNIT[u] + CONTACT_EPISODE[e],
                    "track_cm_s": track + TRACK_UNIT[u] + TRACK_EPISODE[e],
                    "command_x": 0.3 + 0.1 * u,
                }
            )
    return rows


def results_frame(folder: str, cells: pd.DataFrame, units: int, episodes: int) -> pd.DataFrame:
    rows = []
    for cell in cells[cells.folder == folder].itertuples():
        for row in cell_episodes(cell.failures, cell.contacts, cell.track, units, episodes):
            rows.append(
                {
                    "run": folder,
                    "cell_terrain": cell.terrain,
                    "cell_difficulty": cell.difficulty,
                    **row,
                }
            )
    return pd.DataFrame(rows)


def train_curve(index: int) -> pd.DataFrame:
    it = np.arange(CURVE_ITERATIONS)
    reward = 10.0 * (1.0 - np.exp(-it / 5.0)) + index + 0.3 * np.sin(it)
    reward[0] = np.nan  # no finished episode yet, as in a real run's first iteration
    return pd.DataFrame(
        {
            "iteration": it,
            "env_steps": (it + 1) * 8 * 24,
            "stage": ["blind"] * (CURVE_ITERATIONS // 2) + ["perception"] * (CURVE_ITERATIONS // 2),
            "mean_reward": reward,
        }
    )


def build_fixture_store(root: Path) -> Path:
    """The hand-made run store under `root` (created); returns `root`."""
    spec, cells = fixture_spec(), fixture_cells()
    root.mkdir(parents=True, exist_ok=True)
    for index, run in enumerate(spec["runs"]):
        path = root / run["folder"]
        path.mkdir()
        overrides = [f"policy={run['policy']}", f"seed={run['seed']}"]
        cfg = compose(overrides)
        (path / "config.yaml").write_text(OmegaConf.to_yaml(cfg, resolve=True))
        provenance = {
            "overrides": overrides,
            "choices": {"policy": run["policy"]},
            "seed": run["seed"],
            "git": {"commit": run["commit"], "dirty": run["dirty"]},
        }
        (path / "provenance.json").write_text(json.dumps(provenance, indent=2))
        train_curve(index).to_csv(path / "train_curve.csv", index=False)
        if run.get("results", True):  # an evaluated run is complete; the others are not
            frame = results_frame(run["folder"], cells, spec["units"], spec["episodes"])
            frame.to_parquet(path / "results.parquet", index=False)
            (path / "COMPLETE").write_text("{}")
    (root / NOT_A_RUN).mkdir()
    (root / NOT_A_RUN / "README.txt").write_text("not a run directory\n")
    return root


def cell_units(frame: pd.DataFrame, terrain: str, difficulty: str, metric: str) -> pd.Series:
    """Per-unit means of `metric` in one cell of a results frame, computed here from scratch."""
    cell = frame[(frame.cell_terrain == terrain) & (frame.cell_difficulty == difficulty)]
    return cell.groupby("unit")[metric].mean()


CI_COLUMNS = ("ci_low", "ci_high")  # checked against an independent bootstrap instead


def check_golden(produced: Path, name: str) -> None:
    """`produced` must equal golden/<name> (LCA_UPDATE_GOLDEN=1 rewrites it): a CSV cell by
    cell, numbers to a relative 1e-9 (a library's float rounding is not a regression) and
    without the bootstrap CI columns; any other file byte for byte."""
    golden = GOLDEN / name
    # under CI a rewrite would compare the output with itself
    assert not (UPDATE_GOLDEN and os.environ.get("CI")), "LCA_UPDATE_GOLDEN is set under CI"
    if UPDATE_GOLDEN:
        golden.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(produced, golden)
    assert golden.is_file(), f"missing {golden}; generate it with LCA_UPDATE_GOLDEN=1"
    if produced.suffix != ".csv":
        assert produced.read_text() == golden.read_text(), f"{produced} differs from {golden}"
        return
    got, want = pd.read_csv(produced), pd.read_csv(golden)
    assert list(got.columns) == list(want.columns), f"{name}: columns differ"
    assert len(got) == len(want), f"{name}: {len(got)} rows, golden {len(want)}"
    for column in got.columns:
        if column in CI_COLUMNS:
            continue
        a, b = got[column], want[column]
        if pd.api.types.is_numeric_dtype(a) and pd.api.types.is_numeric_dtype(b):
            close = np.isclose(a, b, rtol=1e-9, atol=1e-12, equal_nan=True)
            assert close.all(), f"{name}.{column} rows {np.flatnonzero(~close).tolist()} differ"
        else:
            assert a.astype(str).tolist() == b.astype(str).tolist(), f"{name}.{column} differs"


def percentile_bootstrap(values: np.ndarray, confidence: float, resamples: int, seed: int):
    """The percentile bootstrap CI of the mean, written out: resample units with replacement,
    take the mean of each resample, read the two tail quantiles."""
    rng = np.random.default_rng(seed)
    picks = rng.integers(0, len(values), size=(resamples, len(values)))
    means = np.asarray(values, float)[picks].mean(axis=1)
    tail = (1 - confidence) / 2 * 100
    return np.percentile(means, tail), np.percentile(means, 100 - tail)


CHROMIUM = "/usr/bin/chromium"
CHROMIUM_FLAGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
]


def chromium() -> str:
    """Chromium's path; skips the test, saying why, where there is none."""
    if not Path(CHROMIUM).exists() and shutil.which("chromium") is None:
        pytest.skip(f"no Chromium at {CHROMIUM} or on PATH; cannot render the dashboard")
    return CHROMIUM if Path(CHROMIUM).exists() else shutil.which("chromium")


MEASURE = """<script>
function lcaMeasure() {
  const out = [];
  for (const el of document.querySelectorAll("figure video, figure img")) {
    const box = el.getBoundingClientRect();
    out.push({tag: el.tagName, src: el.getAttribute("src"), poster: el.getAttribute("poster"),
              width: box.width, height: box.height, videoWidth: el.videoWidth ?? null,
              videoHeight: el.videoHeight ?? null, naturalWidth: el.naturalWidth ?? null});
  }
  const pre = document.createElement("pre");
  pre.id = "lca-measured";
  pre.textContent = JSON.stringify(out);
  document.body.appendChild(pre);
}
window.addEventListener("load", () => {
  const videos = [...document.querySelectorAll("video")];
  Promise.all(videos.map(v => v.readyState >= 1 ? 1 : new Promise(done => {
    v.addEventListener("loadedmetadata", done);
    v.addEventListener("error", done);
  }))).then(lcaMeasure);
});
</script>"""


def chromium_media(index: Path, profile: Path) -> list[dict]:
    """Every video and image inside a <figure> of the page `index`, as headless Chromium lays
    it out once the videos' metadata loaded: tag, src, on-screen width and height, and the
    decoded size (videoWidth/videoHeight, naturalWidth). The page is measured through a copy
    beside it (so relative paths resolve the same) with a script added."""
    measured = index.with_name(f"_measure_{index.name}")
    measured.write_text(index.read_text().replace("</body>", MEASURE + "</body>"))
    try:
        out = subprocess.run(
            [chromium(), *CHROMIUM_FLAGS, f"--user-data-dir={profile}"]
            + ["--virtual-time-budget=20000", "--dump-dom", measured.as_uri()],
            capture_output=True,
            text=True,
            timeout=90,
            check=False,
        )
    finally:
        measured.unlink()
    assert out.returncode == 0, out.stderr[-3000:]
    found = re.search(r'<pre id="lca-measured">(.*?)</pre>', out.stdout, re.S)
    assert found, f"the page never finished loading its media: {out.stdout[-1500:]}"
    return json.loads(html.unescape(found.group(1)))


def run_sweep(root: Path, args: list[str], runs: int, timeout: int = 600) -> Path:
    """`python run.py <args>` into `root/runs`; checks that `runs` runs finished and that the
    sweep report was built. Returns the run store."""
    runs_root = root / "runs"
    out = run_python(
        str(REPO / "run.py"), *args, f"runs_root={runs_root}", cwd=root, timeout=timeout
    )
    assert out.returncode == 0, out.stdout[-3000:] + out.stderr[-3000:]
    assert out.stdout.count("[lca] done") == runs, out.stdout
    assert f"[lca] sweep report: {runs_root / 'report' / 'index.html'}" in out.stdout
    return runs_root
