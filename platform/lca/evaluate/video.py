"""Clips on disk: an overlay of the command against the measured velocity on every frame,
encoded as H.264 MP4 by imageio-ffmpeg's own ffmpeg binary, or as a GIF (Pillow, through
imageio) where that binary cannot run.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import imageio.v3 as iio
import numpy as np
from PIL import Image, ImageDraw, ImageFont

from lca.store import write_atomically

COMMAND, MEASURED = (250, 204, 21), (56, 189, 248)  # yellow, cyan
HISTORY_S = 3.0  # s of forward velocity in the strip chart
CHART = (96, 34)  # px
SPEED_RANGE = (-0.2, 1.0)  # m/s shown by the chart (the evaluation commands 0.3-0.6 m/s)


@dataclass
class Telemetry:
    """What the overlay shows on one frame."""

    time_s: float
    command: np.ndarray  # (3,) vx, vy (m/s), wz (rad/s) in the base frame
    velocity: np.ndarray  # (3,) the same, measured
    note: str = ""  # a banner: "fell", "goal reached", ...


def _font(size: int):
    return ImageFont.load_default(size=size)


def overlay(frame: np.ndarray, label: str, now: Telemetry, history: list[Telemetry]) -> np.ndarray:
    """`frame` with the label and clock, command and measured velocity as numbers, and a
    strip chart of both forward velocities over the last HISTORY_S seconds."""
    image = Image.fromarray(frame).convert("RGBA")
    layer = Image.new("RGBA", image.size, (0, 0, 0, 0))
    draw = ImageDraw.Draw(layer)
    font = _font(10)
    draw.rectangle((2, 2, 178, 44), fill=(0, 0, 0, 140))
    draw.text((6, 4), f"{label}   t {now.time_s:4.1f} s", font=font, fill=(255, 255, 255))
    for row, (name, values, colour) in enumerate(
        (("cmd", now.command, COMMAND), ("meas", now.velocity, MEASURED))
    ):
        y = 17 + 13 * row
        draw.text((6, y), name, font=font, fill=colour)
        for col, (axis, value) in enumerate(zip(("vx", "vy", "wz"), values, strict=True)):
            draw.text((38 + 47 * col, y), f"{axis} {value:+.2f}", font=font, fill=colour)
    _chart(draw, image.size, history)
    if now.note:
        width = draw.textlength(now.note, font=_font(12))
        x = image.size[0] - width - 10
        draw.rectangle((x - 4, 4, image.size[0] - 4, 22), fill=(220, 38, 38, 220))
        draw.text((x, 6), now.note, font=_font(12), fill=(255, 255, 255))
    return np.asarray(Image.alpha_composite(image, layer).convert("RGB"))


def _chart(draw: ImageDraw.ImageDraw, size: tuple[int, int], history: list[Telemetry]) -> None:
    w, h = CHART
    x0, y0 = size[0] - w - 6, size[1] - h - 6
    draw.rectangle((x0 - 2, y0 - 2, x0 + w + 2, y0 + h + 2), fill=(0, 0, 0, 140))
    low, high = SPEED_RANGE

    def y(v: float) -> float:
        return y0 + h * (1 - (np.clip(v, low, high) - low) / (high - low))

    draw.line((x0, y(0.0), x0 + w, y(0.0)), fill=(255, 255, 255, 90))
    if len(history) < 2:
        return
    t_end = history[-1].time_s
    recent = [s for s in history if s.time_s >= t_end - HISTORY_S]
    for key, colour in (("command", COMMAND), ("velocity", MEASURED)):
        points = [
            (x0 + w * (1 - (t_end - s.time_s) / HISTORY_S), y(getattr(s, key)[0])) for s in recent
        ]
        if len(points) > 1:
            draw.line(points, fill=colour, width=1)


def write_clip(path: Path, frames: list[np.ndarray], fps: float) -> Path:
    """`frames` as an MP4 at `path`, or, if imageio-ffmpeg cannot encode here (or `path` ends
    in .gif), as a GIF beside it (same stem). Returns the file written; it appears complete
    or not at all."""
    path = Path(path)
    if path.suffix.lower() == ".gif":
        return write_gif(path, frames, fps)
    try:
        return write_atomically(path, lambda tmp: _encode(tmp, frames, fps), path.suffix)
    except (ImportError, RuntimeError, OSError):  # no encoder binary here: a GIF instead
        return write_gif(path.with_suffix(".gif"), frames, fps)


def _encode(path: str, frames: list[np.ndarray], fps: float) -> None:
    import imageio_ffmpeg  # ships its own ffmpeg binary

    height, width = frames[0].shape[:2]
    encoder = imageio_ffmpeg.write_frames(
        str(path),
        (width, height),
        fps=fps,
        codec="libx264",
        pix_fmt_out="yuv420p",  # what every browser decodes
        quality=7,
        macro_block_size=2,
        ffmpeg_log_level="error",
        output_params=["-movflags", "+faststart"],  # playable while it loads
    )
    encoder.send(None)  # starts ffmpeg; raises here if it cannot run
    try:
        for frame in frames:
            encoder.send(np.ascontiguousarray(frame))
    finally:
        encoder.close()


def write_gif(path: Path, frames: list[np.ndarray], fps: float) -> Path:
    stack = np.stack(frames)
    return write_atomically(
        path,
        lambda tmp: iio.imwrite(tmp, stack, extension=".gif", duration=1000.0 / fps, loop=0),
    )


def write_png(path: Path, frame: np.ndarray) -> Path:
    return write_atomically(path, lambda tmp: iio.imwrite(tmp, frame, extension=".png"))
