"""Clips and terrain previews on the dashboard. The report renders nothing: it copies what the
evaluation stages left in each run directory (clips/, terrain/) into media/ and embeds it with
relative paths. Here the files are real (the project's MP4, GIF and PNG writers on synthetic
frames), so these tests need no OpenGL; headless Chromium must show the videos decoded and
every picture at a non-zero size."""

from __future__ import annotations

from html.parser import HTMLParser
from pathlib import Path

import numpy as np
import pytest

from lca.evaluate.video import write_clip, write_gif, write_png
from lca.report.build import build_report

from .helpers import build_fixture_store, chromium_media

pytestmark = pytest.mark.slow  # trains, evaluates or runs a stage: see README

BLIND = "aaa_policy=two_cnn"  # the Blind run of fixtures/runs.yaml
ONE_MLP = "policy=two_mlp,seed=0"  # the One-Stage MLP run
FPS = 25


def frames(n: int, colour: tuple[int, int, int]) -> list[np.ndarray]:
    """A square moving across a coloured field, 320 x 240."""
    out = []
    for i in range(n):
        frame = np.empty((240, 320, 3), np.uint8)
        frame[:] = colour
        frame[100:140, 10 + 10 * i : 50 + 10 * i] = 255
        out.append(frame)
    return out


class Figures(HTMLParser):
    """(section id, tag, attributes) of every video and img, and every figure caption."""

    def __init__(self):
        super().__init__()
        self.section = ""
        self.media: list[tuple[str, str, dict]] = []
        self.captions: list[tuple[str, str]] = []
        self._caption: list | None = None

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        if tag == "h2":
            self.section = attrs.get("id", "")
        elif tag in ("video", "img"):
            self.media.append((self.section, tag, attrs))
        elif tag == "figcaption":
            self._caption = [self.section, ""]

    def handle_endtag(self, tag):
        if tag == "figcaption" and self._caption is not None:
            self.captions.append(tuple(self._caption))
            self._caption = None

    def handle_data(self, data):
        if self._caption is not None:
            self._caption[1] += data


@pytest.fixture(scope="module")
def media_report(tmp_path_factory) -> Path:
    """The fixture store with pictures in two runs, and its report folder."""
    store = build_fixture_store(tmp_path_factory.mktemp("media") / "store")
    blind, one = store / BLIND, store / ONE_MLP
    clip = write_clip(blind / "clips" / "stairs-medium.mp4", frames(20, (40, 90, 160)), FPS)
    assert clip.suffix == ".mp4"
    write_png(blind / "clips" / "stairs-medium.png", frames(1, (40, 90, 160))[0])
    write_clip(blind / "clips" / "hw_stair_ascent.mp4", frames(12, (90, 40, 40)), FPS)
    write_gif(one / "clips" / "uneven-hard.gif", frames(8, (30, 120, 60)), FPS)
    (one / "clips" / "media.json").write_text("{}")  # not a picture: ignored
    terrain = frames(1, (200, 180, 120))[0]
    for run in (blind, one):  # the same training terrain: stored and shown once
        write_png(run / "terrain" / "train.png", terrain)
    write_png(blind / "terrain" / "stairs-medium.png", frames(1, (10, 10, 10))[0])
    out = store / "report"
    build_report([store], out)
    return out


def parsed(report: Path) -> Figures:
    page = Figures()
    page.feed((report / "index.html").read_text())
    return page


def test_pictures_embedded_with_relative_paths(media_report: Path) -> None:
    page = parsed(media_report)
    pictures = [a for section, _, a in page.media if section in ("clips", "terrains")]
    sources = [a["src"] for a in pictures] + [a["poster"] for a in pictures if a.get("poster")]
    assert sources
    for src in sources:
        assert src.startswith("media/"), src  # relative: the page works from file://
        assert (media_report / src).is_file(), src
    clips = [(tag, a["src"]) for section, tag, a in page.media if section == "clips"]
    kinds = [(tag, Path(src).suffix) for tag, src in clips]
    # Blind's cell clip, then its hardware clip; One-Stage MLP's GIF as an image
    assert kinds == [("video", ".mp4"), ("video", ".mp4"), ("img", ".gif")]
    videos = [a for section, tag, a in page.media if tag == "video"]
    assert all(v.get("poster") for v in videos[:1]) and "poster" not in videos[1]
    captions = [text for section, text in page.captions if section == "clips"]
    assert captions == ["stairs-medium", "hardware: stair_ascent", "uneven-hard"]


def test_shared_terrain_shown_once(media_report: Path) -> None:
    page = parsed(media_report)
    terrains = [a["src"] for section, tag, a in page.media if section == "terrains"]
    assert len(terrains) == 2  # train.png of both runs (identical) + Blind's stairs-medium
    captions = [text for section, text in page.captions if section == "terrains"]
    train = next(c for c in captions if c.startswith("training"))
    assert BLIND in train and ONE_MLP in train
    assert "evaluation cell stairs-medium" in captions


def test_chromium_shows_videos_and_images(media_report: Path, tmp_path: Path) -> None:
    shown = chromium_media(media_report / "index.html", tmp_path / "profile")
    videos = [m for m in shown if m["tag"] == "VIDEO"]
    images = [m for m in shown if m["tag"] == "IMG"]
    seed_figures = [m for m in images if m["src"].startswith(("seeds_", "performance_profiles"))]
    assert seed_figures, shown  # the training-seed section's figures (report/seeds.py)
    images = [m for m in images if m not in seed_figures]
    assert len(videos) == 2 and len(images) == 3, shown
    for item in shown:
        assert item["width"] > 0 and item["height"] > 0, item
        assert (media_report / item["src"]).is_file(), item
    for video in videos:  # Chromium decoded the MP4: its frames are 320 x 240
        assert (video["videoWidth"], video["videoHeight"]) == (320, 240), video
    for image in images:
        assert image["naturalWidth"] > 0, image  # the file decoded
    gif = next(m for m in images if m["src"].endswith(".gif"))
    assert gif["naturalWidth"] == 320


def test_runs_without_pictures_have_no_sections(fixture_report: Path) -> None:
    page = parsed(fixture_report)
    assert not page.media or {s for s, _, _ in page.media} <= {"training", "seeds"}
    html = (fixture_report / "index.html").read_text()
    assert 'id="clips"' not in html and 'id="terrains"' not in html
    assert not (fixture_report / "media").exists()
