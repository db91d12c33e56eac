"""See the robot: clips of a trained policy under the evaluation protocol.

A clip films one unit from a tracking camera, with the command and the measured velocity
drawn over it: an evaluation cell's settings, seeded like the cell's first round, or a
hardware task's first trial (`lca.evaluate.hardware.hardware_setting`), on the run's final
policy. `lca.evaluate.media` makes the clips a run keeps; `lca.play` films any cell or task
for any length.
"""

from __future__ import annotations

import copy
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import torch
from omegaconf import DictConfig

from lca.arrays import to_numpy
from lca.evaluate.policy import load_policy, sees_map
from lca.evaluate.protocol import cell_config, cell_name, round_seed
from lca.evaluate.rollout import rollout, start
from lca.evaluate.video import Telemetry, overlay, write_clip, write_png
from lca.sim import render
from lca.sim.terrain import Terrain
from lca.task.env import LocomotionEnv
from lca.task.state import yaw_of

MIN_FPS = 20
MARGIN = 3.0  # m of terrain drawn around the filmed path
NOTE_S = 1.0  # s a banner stays up
HOLD_S = 0.6  # s the last frame stays after a hardware trial ends
AFTER_GOAL_S = 1.0  # s filmed after a hardware trial reaches its goal


@dataclass
class Recording:
    fps: float
    qpos: list[np.ndarray] = field(default_factory=list)
    telemetry: list[Telemetry] = field(default_factory=list)

    def __len__(self) -> int:
        return len(self.qpos)


def frame_stride(dt: float) -> int:
    """Policy steps per frame: the most that still gives at least MIN_FPS."""
    return max(1, int(1.0 / (MIN_FPS * dt) + 1e-9))


def clip_fps(dt: float) -> float:
    return 1.0 / (frame_stride(dt) * dt)


def gl_missing(run_name: str, log) -> bool:
    """True (saying so in one line) when MuJoCo cannot render in this process."""
    reason = render.gl_unavailable()
    if reason and log:
        log(
            f"[lca] clips skipped for {run_name}: MuJoCo cannot render here ({reason}); "
            f"eval.videos=false turns clips off"
        )
    return reason is not None


@torch.inference_mode()
def record(
    env: LocomotionEnv, policy, frames: int, goal: Callable[[dict], bool] | None = None
) -> Recording:
    """Unit 0 of `env` from a reset, at most `frames` frames at `clip_fps`.

    Without `goal` (an evaluation cell) a fall restarts the unit's episode under a banner.
    With `goal(metrics)` (a hardware trial) the recording ends AFTER_GOAL_S after the goal is
    reached, or when the trial falls or runs out of time; the env has already reset the unit
    then, so its last frame is held, captioned."""
    stride = frame_stride(env.dt)
    rec = Recording(fps=clip_fps(env.dt))
    steps_taken = rollout(env, policy, start(env, policy), steps=None)
    note, note_frames, steps = "", 0, 0

    def capture(text: str) -> None:
        s = env.state
        lin, ang = to_numpy(s.base_lin_vel[0]), to_numpy(s.base_ang_vel[0])
        velocity = np.array([lin[0], lin[1], ang[2]], dtype=np.float64)
        rec.qpos.append(to_numpy(env.sim.qpos[0]).astype(np.float64))
        command = to_numpy(env.commands.value[0]).astype(np.float64)
        rec.telemetry.append(Telemetry(steps * env.dt, command, velocity, text))

    capture("")
    last_frame = frames  # a trial past its goal is filmed a little longer, then stops
    while len(rec) < last_frame:
        ended = ""
        for _ in range(stride):
            _, m = next(steps_taken)
            steps += 1
            if m["terminated"][0] or (goal is not None and m["time_out"][0]):
                ended = "fell" if m["terminated"][0] else "time limit"
                break
            if goal is not None and last_frame == frames and goal(m):
                note, note_frames = "goal reached", frames
                last_frame = min(frames, len(rec) + 1 + int(AFTER_GOAL_S * rec.fps))
        if ended and goal is not None:
            last = rec.telemetry[-1]
            for _ in range(min(int(HOLD_S * rec.fps), frames - len(rec))):
                rec.qpos.append(rec.qpos[-1])
                rec.telemetry.append(Telemetry(last.time_s, last.command, last.velocity, ended))
            break
        if ended:
            note, note_frames = "fell: new episode", int(NOTE_S * rec.fps)
        capture(note if note_frames > 0 else "")
        note_frames -= 1
    return rec


def film(
    cfg: DictConfig,
    terrain: Terrain,
    rec: Recording,
    label: str,
    decorate: render.Decorate | None = None,
    ground: Callable[..., Terrain] = render.window,
) -> list[np.ndarray]:
    """The frames of `rec` from a camera tracking the robot, with the velocity overlay.
    `ground(terrain, lo, hi)`: what the render model draws of the terrain around the path
    (`render.crop` draws its samples, as clips did before `render.window`)."""
    path = np.array([q[:2] for q in rec.qpos])
    near = ground(terrain, path.min(0) - MARGIN, path.max(0) + MARGIN)
    camera = render.TrackingCamera(render.render_scene(cfg, near, decorate).model)
    frames, heading = [], 0.0
    try:
        for i, (qpos, now) in enumerate(zip(rec.qpos, rec.telemetry, strict=True)):
            yaw = float(yaw_of(qpos[3:7]))
            if i == 0 or np.linalg.norm(qpos[:2] - rec.qpos[i - 1][:2]) > 0.5:
                heading = yaw  # a new episode: cut, don't pan
            heading += 0.1 * math.remainder(yaw - heading, 2 * math.pi)  # calm on the gait
            image = camera.frame(qpos, heading)
            frames.append(overlay(image, label, now, rec.telemetry[: i + 1]))
    finally:
        camera.close()
    return frames


def save(frames: list[np.ndarray], fps: float, out: Path) -> Path:
    """The clip at `out` (.mp4, or a .gif beside it) and its poster frame, a third of the way
    in, at `out` with suffix .png. Returns the clip's path."""
    out = Path(out)
    clip = write_clip(out, frames, fps)
    write_png(out.with_suffix(".png"), frames[len(frames) // 3])
    return clip


def clip_config(cfg: DictConfig, seconds: float) -> DictConfig:
    """One unit; episodes no shorter than the clip, so it never shows a time-out reset."""
    c = copy.deepcopy(cfg)
    c.task.num_envs = 1
    c.task.episode_length_s = max(float(c.task.episode_length_s), seconds + 1.0)
    return c


@dataclass
class Setting:
    """What a clip films: one unit's env, seeded, with the policy loaded."""

    cfg: DictConfig  # the setting's config (one unit)
    env: LocomotionEnv
    policy: Callable
    label: str
    terrain: Terrain  # the simulated one, whole
    decorate: render.Decorate | None = None  # task objects of a hardware scene
    goal: Callable[[dict], bool] | None = None  # a hardware trial's goal (see `record`)


@dataclass
class Clip:
    frames: list[np.ndarray]
    fps: float


def cell_setting(cfg: DictConfig, cell, checkpoint: Path, seconds: float) -> Setting:
    """One unit of evaluation `cell`, seeded like the cell's first round, for `seconds`."""
    c = clip_config(cell_config(cfg, cell), seconds)
    env = LocomotionEnv(c)
    env.set_perception(sees_map(checkpoint))
    policy = load_policy(c, env, checkpoint)
    env.reseed(round_seed(c.eval.seed, cell, 0))
    return Setting(c, env, policy, cell_name(cell), env.scene.terrain)


def shoot(setting: Setting, seconds: float) -> Clip:
    """`seconds` of the setting (less if a hardware trial ends first), filmed."""
    env = setting.env
    rec = record(env, setting.policy, max(1, round(seconds * clip_fps(env.dt))), setting.goal)
    frames = film(setting.cfg, setting.terrain, rec, setting.label, setting.decorate)
    return Clip(frames, rec.fps)
