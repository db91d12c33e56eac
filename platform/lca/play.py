"""Watch a trained policy: a clip, or MuJoCo's viewer driven by the policy.

    python -m lca.play run_dir=<run> [cell=stairs-hard] [out=clip.mp4] [seconds=10]
    python -m lca.play run_dir=<run> task=stair_ascent        # a hardware-style task
    python -m lca.play run_dir=<run> cell=uneven-hard --viewer  # needs a display

The rollout uses the evaluation protocol's settings for the cell (one unit, seeded like the
cell's first round) or the hardware protocol's for the task, on the run's final policy;
other `key=value` arguments override the run's config as in `python -m lca.evaluate`. The
clip is an MP4 (a GIF where MP4 cannot be encoded) at 25 frames per second from a tracking
camera, with the command and the measured velocity drawn over it. Default cell: the run's
first evaluation cell; default out: `<run name>_<cell or task>.mp4`.
"""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path

import torch

from lca.arrays import to_numpy
from lca.cli import split_option
from lca.config import ConfigError
from lca.evaluate.clips import Setting, cell_setting, save, shoot
from lca.evaluate.config import parse_cell
from lca.evaluate.hardware import hardware_setting
from lca.evaluate.policy import final_checkpoint, load_run_config
from lca.evaluate.protocol import cell_name
from lca.sim.config import HARDWARE_TASKS
from lca.sim.render import gl_unavailable

USAGE = (
    "usage: python -m lca.play run_dir=<run> [cell=<terrain>-<difficulty> | task=<hardware "
    "task>] [out=PATH.mp4] [seconds=S] [--viewer] [key=value ...]"
)


def _one(args: list[str], key: str) -> tuple[str | None, list[str]]:
    values, rest = split_option(args, key)
    if len(values) > 1:
        raise ConfigError(f"{key}: given {len(values)} times")
    return (values[0] if values else None), rest


def view(setting: Setting) -> None:
    """MuJoCo's viewer on the setting's model, the policy stepping it in real time; a fall
    or a time-out starts a new episode. Runs until the window closes."""
    import mujoco.viewer

    env, policy = setting.env, setting.policy
    model = env.scene.model
    data = mujoco.MjData(model)
    with torch.inference_mode(), mujoco.viewer.launch_passive(model, data) as viewer:
        obs = env.reset_all()
        policy.reset(torch.ones(env.num_envs, dtype=torch.bool, device=env.device))
        while viewer.is_running():
            start = time.perf_counter()
            obs, _, dones, _ = env.step(policy(obs))
            policy.reset(dones.bool())
            data.qpos[:] = to_numpy(env.sim.qpos[0])
            mujoco.mj_forward(model, data)
            viewer.sync()
            time.sleep(max(0.0, env.dt - (time.perf_counter() - start)))


def main(argv: list[str] | None = None) -> int:
    args = list(sys.argv[1:] if argv is None else argv)
    viewer = "--viewer" in args
    args = [a for a in args if a != "--viewer"]
    try:
        run_dir, args = _one(args, "run_dir")
        cell_text, args = _one(args, "cell")
        task, args = _one(args, "task")
        out, args = _one(args, "out")
        seconds_text, overrides = _one(args, "seconds")
        if run_dir is None:
            print(USAGE, file=sys.stderr)
            return 2
        if cell_text and task:
            raise ConfigError("cell, task: give one of them, not both")
        if task is not None and task not in HARDWARE_TASKS:
            raise ConfigError(f"task: unknown '{task}'; allowed: {HARDWARE_TASKS}")
        try:
            seconds = float(seconds_text) if seconds_text is not None else 10.0
        except ValueError:
            raise ConfigError(f"seconds: not a number: '{seconds_text}'") from None
        if not seconds > 0:
            raise ConfigError(f"seconds: must be > 0, got {seconds_text}")
        cfg = load_run_config(Path(run_dir), overrides)
        cell = parse_cell(cell_text) if cell_text else None
        if cell is None and task is None:
            cell = cfg.eval.cells[0]
        headless = not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))
        if viewer and sys.platform == "linux" and headless:
            raise ConfigError("--viewer: needs a display (DISPLAY or WAYLAND_DISPLAY is unset)")
        reason = None if viewer else gl_unavailable()
        if reason:
            raise ConfigError(f"out: cannot render a clip here: {reason}")
    except ConfigError as error:
        print(f"error: {error}", file=sys.stderr)
        return 2
    checkpoint = final_checkpoint(Path(run_dir))
    if task is not None:
        setting, name = hardware_setting(cfg, task, checkpoint), task
    else:
        setting, name = cell_setting(cfg, cell, checkpoint, seconds), cell_name(cell)
    if viewer:
        view(setting)
        return 0
    path = Path(out) if out else Path(f"{Path(run_dir).resolve().name}_{name}.mp4")
    start = time.perf_counter()
    clip = shoot(setting, seconds)
    written = save(clip.frames, clip.fps, path)
    print(
        f"wrote {written} ({len(clip.frames)} frames at {clip.fps:g} fps, "
        f"{written.stat().st_size / 1e6:.2f} MB, {time.perf_counter() - start:.1f} s) "
        f"and its poster {path.with_suffix('.png')}"
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
