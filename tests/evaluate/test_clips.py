"""Seeing the robot after evaluation: clips per cell and per hardware task, terrain previews,
`eval.videos`, and `python -m lca.play`. Clips are read back from disk (frames, size, rate);
tests that need OpenGL skip, saying why, where MuJoCo cannot render."""

from __future__ import annotations

import ctypes.util
import os
import shutil
import subprocess
import sys
from pathlib import Path

import imageio.v3 as iio
import imageio_ffmpeg
import matplotlib.image
import pytest

from lca.config import compose
from lca.evaluate.hardware import run_hardware
from lca.evaluate.media import make_media
from lca.evaluate.policy import load_run_config
from lca.evaluate.run import evaluate_and_write
from lca.sim.render import HEIGHT, WIDTH, gl_unavailable

from .helpers import REPO, cli_env, run_module, train_tiny_run

pytestmark = pytest.mark.slow  # trains, evaluates or runs a stage: see README

SHIPPED = REPO / "assets" / "policies" / "blind_flat"
SECONDS, FPS = 0.8, 25  # 20 frames: the policy runs at 50 Hz, a frame every 2 steps
VIDEO = [
    "eval.videos=true",
    f"eval.video_seconds={SECONDS}",
    "eval.cells=[{terrain:stairs,difficulty:hard}]",
]


def needs_gl() -> None:
    reason = gl_unavailable()
    if reason:
        pytest.skip(f"MuJoCo cannot render here: {reason}")


def read_clip(path: Path) -> tuple[dict, list]:
    """(metadata, frames) of an MP4, decoded by ffmpeg."""
    reader = imageio_ffmpeg.read_frames(str(path))
    meta = next(reader)
    return meta, list(reader)


@pytest.fixture(scope="module")
def filmed_run(tmp_path_factory) -> tuple[Path, list[str]]:
    """A tiny trained run evaluated on one cell with `eval.videos=true`, and its log."""
    _, run = train_tiny_run(tmp_path_factory.mktemp("clips") / "filmed", *VIDEO)
    lines: list[str] = []
    evaluate_and_write(run.path, log=lines.append)
    return run.path, lines


def test_cell_clip_read_back(filmed_run) -> None:
    needs_gl()
    run, lines = filmed_run
    clip = run / "clips" / "stairs-hard.mp4"
    meta, frames = read_clip(clip)
    assert meta["size"] == (WIDTH, HEIGHT) and meta["fps"] == FPS
    assert len(frames) == round(SECONDS * FPS)
    assert len(frames[0]) == WIDTH * HEIGHT * 3
    poster = iio.imread(run / "clips" / "stairs-hard.png")
    assert poster.shape == (HEIGHT, WIDTH, 3) and poster.std() > 10
    assert any(line.startswith("[lca] media filmed stairs-hard") for line in lines), lines


def test_terrain_previews_written(filmed_run) -> None:
    run, _ = filmed_run
    for name in ("train", "stairs-hard"):
        image = matplotlib.image.imread(run / "terrain" / f"{name}.png")
        assert image.shape[:2] == (420, 1100) and image[..., :3].std() > 0.05, name


def test_media_made_once_and_again_when_settings_change(filmed_run, tmp_path: Path) -> None:
    needs_gl()
    run = tmp_path / "run"
    shutil.copytree(filmed_run[0], run)
    clip = run / "clips" / "stairs-hard.mp4"
    before = clip.stat().st_mtime_ns
    assert make_media(run, load_run_config(run)) == []  # up to date: nothing made
    assert clip.stat().st_mtime_ns == before
    lines: list[str] = []
    evaluate_and_write(run, ["eval.video_seconds=0.4"], log=lines.append)
    assert not any("discarding" in line for line in lines)  # clip settings are not protocol
    assert not any(line.startswith("[lca] eval ") for line in lines)  # no round re-run
    _, frames = read_clip(clip)
    assert len(frames) == round(0.4 * FPS)


def test_videos_off_at_smoke_scale(evaluated_run) -> None:
    _, run, _ = evaluated_run  # evaluated at scale=smoke without eval.videos
    assert not (run / "clips").exists() and not (run / "terrain").exists()
    assert compose(["scale=smoke"]).eval.videos is False
    assert compose([]).eval.videos is True


def test_evaluation_without_gl_skips_clips(filmed_run, tmp_path: Path) -> None:
    """MUJOCO_GL=disable: MuJoCo has no OpenGL at all, as on a machine without the libraries."""
    run = tmp_path / "run"
    shutil.copytree(filmed_run[0], run, ignore=shutil.ignore_patterns("clips", "terrain"))
    env = cli_env() | {"MUJOCO_GL": "disable"}
    out = run_module("lca.evaluate", f"run_dir={run}", cwd=tmp_path, timeout=300, env=env)
    assert out.returncode == 0, out.stderr[-3000:]
    skipped = [line for line in out.stdout.splitlines() if "clips skipped" in line]
    assert len(skipped) == 1 and "MUJOCO_GL=disable" in skipped[0], out.stdout[-2000:]
    assert (run / "results.parquet").exists() and (run / "summary.csv").exists()
    assert not list((run / "clips").glob("*.mp4"))
    assert (run / "terrain" / "stairs-hard.png").exists()  # the height map needs no GL


def test_hardware_clip(filmed_run, tmp_path: Path) -> None:
    """`run_hardware` with eval.videos films each task's first trial: the hinged ledge (a task
    object with its own joint) until the trial's one-second time limit, last frame held."""
    needs_gl()
    run = tmp_path / "run"
    shutil.copytree(filmed_run[0], run)
    cfg = load_run_config(
        run, ["hardware.tasks=[hinged_ledge]", "hardware.trials=1", "hardware.time_limit_s=1"]
    )
    trials = run_hardware(run, cfg, log=None)
    assert list(trials.task) == ["hinged_ledge"]
    meta, frames = read_clip(run / "clips" / "hw_hinged_ledge.mp4")
    assert meta["size"] == (WIDTH, HEIGHT) and meta["fps"] == FPS
    # 1 s of trial (25 frames, less after a fall) and the last frame held 0.6 s (15)
    assert 15 < len(frames) <= FPS + 15


def play(*args: str, cwd: Path, env: dict | None = None) -> subprocess.CompletedProcess:
    return run_module("lca.play", *args, cwd=cwd, timeout=300, env=env)


@pytest.fixture(scope="module")
def shipped_run(tmp_path_factory) -> Path:
    """A copy of the shipped walking policy (assets/ is never written)."""
    run = tmp_path_factory.mktemp("play") / "blind_flat"
    shutil.copytree(SHIPPED, run)
    return run


def test_play_writes_an_mp4(shipped_run: Path, tmp_path: Path) -> None:
    needs_gl()
    clip = tmp_path / "walk.mp4"
    out = play(
        f"run_dir={shipped_run}", "cell=flat-medium", "seconds=1", f"out={clip}", cwd=tmp_path
    )
    assert out.returncode == 0, out.stderr[-3000:]
    assert f"wrote {clip} (25 frames at 25 fps" in out.stdout
    meta, frames = read_clip(clip)
    assert meta["size"] == (WIDTH, HEIGHT) and len(frames) == 25
    assert clip.with_suffix(".png").exists()


def test_play_falls_back_to_gif(shipped_run: Path, tmp_path: Path) -> None:
    """Where imageio-ffmpeg's binary cannot run, the clip is a GIF beside the asked path."""
    needs_gl()
    env = cli_env() | {"IMAGEIO_FFMPEG_EXE": str(tmp_path / "no-ffmpeg")}
    args = [f"run_dir={shipped_run}", "cell=stairs-hard", "seconds=0.4", "out=clip.mp4"]
    out = play(*args, cwd=tmp_path, env=env)
    assert out.returncode == 0, out.stderr[-3000:]
    assert not (tmp_path / "clip.mp4").exists()
    frames = iio.imread(tmp_path / "clip.gif", index=None)
    assert frames.shape == (10, HEIGHT, WIDTH, 3)
    assert iio.immeta(tmp_path / "clip.gif")["duration"] == 1000 / FPS


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["cell=stairs-easy"], "cell: 'stairs-easy' is not <terrain>-<difficulty>"),
        (["cell=stairs-easy"], "unknown 'easy'; allowed: ['hard', 'medium']"),
        (["task=ladder"], "task: unknown 'ladder'; allowed:"),
        (["seconds=-1"], "seconds: must be > 0"),
        (["--viewer"], "--viewer: needs a display"),
    ],
)
def test_play_rejects_bad_arguments(shipped_run: Path, tmp_path: Path, args, message) -> None:
    env = {k: v for k, v in cli_env().items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    out = play(f"run_dir={shipped_run}", *args, cwd=tmp_path, env=env)
    assert out.returncode == 2 and message in out.stderr, out.stderr[-2000:]
    assert not list(tmp_path.glob("*.mp4"))


def test_headless_backend_picked_on_import() -> None:
    """Without a display, importing lca (before MuJoCo) picks EGL, else OSMesa."""
    if sys.platform != "linux" or os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"):
        pytest.skip("only without a display on Linux")
    found = ctypes.util.find_library
    egl = found("EGL") and (found("OpenGL") or found("GL"))
    expected = "egl" if egl else "osmesa" if found("OSMesa") else "None"
    env = {k: v for k, v in cli_env().items() if k != "MUJOCO_GL"}
    code = "import lca, os; print(os.environ.get('MUJOCO_GL'))"
    out = subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True
    )
    assert out.stdout.strip() == expected
