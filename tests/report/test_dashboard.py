"""The dashboard (index.html) of the hand-made run store, rendered by headless Chromium."""

from __future__ import annotations

import subprocess
from html.parser import HTMLParser
from pathlib import Path
from urllib.parse import unquote

import matplotlib.image
import pytest

from .helpers import CHROMIUM_FLAGS as FLAGS
from .helpers import chromium as _chromium
from .helpers import fixture_spec

pytestmark = pytest.mark.slow  # trains, evaluates or runs a stage: see README

POLICIES = ["Blind", "One-Stage MLP", "Two-Stage MLP"]


class Dom(HTMLParser):
    """Tables (attributes, rows of (text, classes) cells), images, links and headings."""

    def __init__(self):
        super().__init__()
        self.tables: list[dict] = []
        self.images: list[str] = []
        self.links: list[tuple[str, str]] = []
        self.headings: list[tuple[str, str]] = []
        self._stack: list[dict] = []
        self._cell: dict | None = None
        self._link: list | None = None
        self._heading: list | None = None

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        if tag == "table":
            table = {
                "attrs": attrs,
                "rows": [],
                "heading": self.headings[-1][1] if self.headings else None,
            }
            self.tables.append(table)
            self._stack.append(table)
        elif tag == "tr" and self._stack:
            self._stack[-1]["rows"].append([])
        elif tag in ("td", "th") and self._stack:
            self._cell = {"tag": tag, "text": "", "classes": set(attrs.get("class", "").split())}
            self._stack[-1]["rows"][-1].append(self._cell)
        elif tag == "img":
            self.images.append(attrs.get("src", ""))
        elif tag == "a":
            self._link = [attrs.get("href", ""), ""]
        elif tag in ("h1", "h2"):
            self._heading = [attrs.get("id", ""), ""]

    def handle_endtag(self, tag):
        if tag == "table" and self._stack:
            self._stack.pop()
        elif tag in ("td", "th"):
            self._cell = None
        elif tag == "a" and self._link is not None:
            self.links.append(tuple(self._link))
            self._link = None
        elif tag in ("h1", "h2") and self._heading is not None:
            self.headings.append(tuple(self._heading))
            self._heading = None

    def handle_data(self, data):
        if self._cell is not None:
            self._cell["text"] += data
        if self._link is not None:
            self._link[1] += data
        if self._heading is not None:
            self._heading[1] += data

    def table_under(self, heading_id: str) -> dict:
        ids = dict(self.headings)
        return next(t for t in self.tables if t["heading"] == ids[heading_id])


@pytest.fixture(scope="module")
def rendered(fixture_report: Path, tmp_path_factory) -> tuple[str, Dom]:
    """`chromium --headless --dump-dom file://.../index.html`: the DOM after parsing."""
    chromium = _chromium()
    profile = tmp_path_factory.mktemp("chromium_profile")
    out = subprocess.run(
        [chromium, *FLAGS, f"--user-data-dir={profile}", "--dump-dom"]
        + [(fixture_report / "index.html").as_uri()],
        capture_output=True,
        text=True,
        timeout=90,
        check=False,
    )
    assert out.returncode == 0, out.stderr[-3000:]
    assert "<body>" in out.stdout, out.stdout[:500]
    dom = Dom()
    dom.feed(out.stdout)
    return out.stdout, dom


def test_sim_table_rendered(rendered) -> None:
    _, dom = rendered
    table = dom.table_under("simulation")
    text = [[c["text"].strip() for c in row] for row in table["rows"]]
    header = " ".join(c for row in text[:2] for c in row)
    for label in ("Stairs", "Uneven Terrain", "R_succ (%, ↑)", "Contacts/step (%, ↓)"):
        assert label in header
    body = [r for r in table["rows"] if any(c["tag"] == "td" for c in r)]
    policies = [next(c["text"].strip() for c in r if c["text"].strip() in POLICIES) for r in body]
    assert policies == POLICIES * 2  # Medium block, then Hard
    cells = [c for r in body for c in r if c["tag"] == "td"]
    assert len(cells) == 6 * 6
    assert any(c["text"] == "0.80 ± 0.13" for c in cells)  # LaTeX \pm rendered as ±
    assert not any("$" in c["text"] or "\\" in c["text"] for c in cells)
    best = [c["text"] for c in cells if "best" in c["classes"]]
    assert len(best) == 2 + 2 + 4 + 1 + 5  # as in the LaTeX table (see test_golden)
    assert "17.60 ± 0.96" in best and "2.80 ± 0.13" in best


def test_sim_table_has_its_id(rendered) -> None:
    _, dom = rendered
    ids = [t["attrs"].get("id") for t in dom.tables]
    assert "sim-table" in ids, ids


def test_claim_table_rendered(rendered) -> None:
    _, dom = rendered
    table = next(t for t in dom.tables if t["attrs"].get("id") == "claim-table")
    assert table is dom.table_under("claim")
    rows = [[c["text"].strip() for c in r] for r in table["rows"]]
    assert rows[0][:3] == ["two_stage", "one_stage", "seed"] and "diff" in rows[0]
    assert len(rows) == 1 + 8
    assert all(r[:3] == ["Two-Stage MLP", "One-Stage MLP", "0"] for r in rows[1:])


def test_training_image(rendered, fixture_report: Path) -> None:
    _, dom = rendered
    # the training figure, then the training-seed section's (one policy has two seeds)
    assert "training_rewards.png" in dom.images
    others = [i for i in dom.images if i != "training_rewards.png"]
    assert others and all(i.startswith(("seeds_", "performance_profiles")) for i in others)
    png = matplotlib.image.imread(fixture_report / "training_rewards.png")
    assert png.shape[0] > 300 and png.shape[1] > 500


def test_runs_table_links_and_commits(rendered, fixture_report: Path) -> None:
    _, dom = rendered
    table = next(t for t in dom.tables if t["attrs"].get("id") == "runs-table")
    rows = [[c["text"].strip() for c in r] for r in table["rows"]]
    assert rows[0] == ["run", "policy", "seed", "commit", "config", "results"]
    by_run = {r[0]: r for r in rows[1:]}
    everything = fixture_spec()["runs"]
    spec = [r for r in everything if r.get("results", True)]  # complete runs only
    assert set(by_run) == {r["folder"] for r in spec}
    excluded = next(t for t in dom.tables if t["attrs"].get("id") == "excluded-table")
    left_out = [[c["text"].strip() for c in r] for r in excluded["rows"][1:]]
    assert [Path(r[0]).name for r in left_out] == [
        r["folder"] for r in everything if not r.get("results", True)
    ]
    assert all(r[1] == "incomplete" for r in left_out)
    labels = {"blind": "Blind", "one_mlp": "One-Stage MLP", "two_mlp": "Two-Stage MLP"}
    labels["one_lstm"] = "One-Stage LSTM"
    for run in spec:
        row = by_run[run["folder"]]
        assert row[1] == labels[run["policy"]] and row[2] == str(run["seed"])
        commit = run["commit"][:10] + (" (dirty)" if run["dirty"] else "")
        assert row[3] == commit
        assert row[5] == ("yes" if run.get("results", True) else "no")
    hrefs = dict((text, href) for href, text in dom.links)
    for run in spec:  # links resolve to the run folder and its config
        folder = (fixture_report / unquote(hrefs[run["folder"]])).resolve()
        assert folder == (fixture_report.parent / run["folder"]).resolve()
        assert folder.is_dir()
    configs = [href for href, text in dom.links if text == "config"]
    assert len(configs) == len(spec)
    assert all((fixture_report / unquote(h)).is_file() for h in configs)
    for name in ("sim_table.tex", "sim_table.csv", "claim.csv"):
        assert any(href == name for href, _ in dom.links), name


def test_screenshot(fixture_report: Path, tmp_path: Path) -> None:
    chromium = _chromium()
    shot = tmp_path / "dashboard.png"
    out = subprocess.run(
        [chromium, *FLAGS, f"--user-data-dir={tmp_path / 'profile'}", "--hide-scrollbars"]
        + ["--window-size=1280,2000", f"--screenshot={shot}"]
        + [(fixture_report / "index.html").as_uri()],
        capture_output=True,
        text=True,
        timeout=90,
        check=False,
    )
    assert out.returncode == 0, out.stderr[-3000:]
    image = matplotlib.image.imread(shot)
    assert image.shape[:2] == (2000, 1280)
    assert image[..., :3].std() > 0.05  # text, tables and the figure: not a blank page
