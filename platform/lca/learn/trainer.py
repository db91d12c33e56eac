"""One training run, top to bottom: env -> rsl-rl PPO -> curriculum -> checkpoints -> export.

The loop is rsl-rl's `OnPolicyRunner.learn` written out, so the curriculum can switch the
actor's perception at an exact iteration, a compact progress line can be printed, curves go
to CSV, and an interrupted run resumes from its last checkpoint. Scalars still go to
tensorboard / wandb through rsl-rl's own logger.
"""

from __future__ import annotations

import contextlib
import copy
import csv
import io
import math
import time
from pathlib import Path

import numpy as np
import torch
from omegaconf import DictConfig
from rsl_rl.runners import OnPolicyRunner

from lca.config.runtime import resolve_device
from lca.learn import curriculum
from lca.learn.checkpoints import LATEST, Checkpoints, set_learning_rate
from lca.learn.command_curriculum import CommandCurriculum
from lca.learn.episode_stats import EpisodeStats
from lca.learn.exploration import apply_ceiling, noise_ceiling, set_initial_stds
from lca.learn.export import export_jit, export_onnx
from lca.learn.interrupt import StopOnSignal, TrainingInterrupted
from lca.learn.reward_curriculum import RewardCurriculum
from lca.learn.train_cfg import build_train_cfg
from lca.learn.variants import actor_spec
from lca.store import RunDir, write_atomically
from lca.task.env import LocomotionEnv
from lca.testhook import exit_point

CURVE_FIELDS = (
    "iteration",
    "env_steps",
    "wall_s",
    "stage",
    "steps_per_s",
    "collect_s",
    "update_s",
    "mean_reward",
    "mean_episode_length",
    "track_lin_vel_xy_exp",
    "track_ang_vel_z_exp",
    "value_loss",
    "surrogate_loss",
    "action_std",
    "learning_rate",
    "kl",
    "penalty_scale",
    "command_floor",
    "command_x_low",
    "tracking_progress",
    "falls",
    "nonfinite",
    "nonfinite_actions",
    "terrain_level",  # mean row of the terrain-level curriculum / top row (terrain.levels)
)
BROKEN_STREAK = 3  # iterations whose every episode ends non-finite before a run fails
MOVING = 0.2  # m/s: commands at least this fast count towards the tracking progress
TRACKED = ("track_error", "command_speed")  # the step metrics the tracking progress sums


def _number(text: str):
    try:
        return float(text)
    except ValueError:
        return text


def _masked_sum(values, mask):
    """Sum of `values` where `mask`: NumPy sums the selection; torch sums a `where`, which
    needs no host sync to size a selection."""
    if isinstance(values, np.ndarray):
        return values[mask].sum()
    return torch.where(mask, values, 0.0).sum()


def _fmt_eta(seconds: float) -> str:
    seconds = int(max(seconds, 0))
    return f"{seconds // 3600:d}:{seconds % 3600 // 60:02d}:{seconds % 60:02d}"


class Trainer(Checkpoints):
    def __init__(self, cfg: DictConfig, run_dir: RunDir, env: LocomotionEnv | None = None):
        self.cfg = cfg
        self.run = run_dir
        run_dir.path.mkdir(parents=True, exist_ok=True)
        self.device = resolve_device(cfg.device)
        self.total = int(cfg.scale.max_iterations)
        torch.manual_seed(int(cfg.seed))
        self.env = env if env is not None else LocomotionEnv(cfg)
        # wandb names a run after the log folder's basename
        log_dir = (
            None if cfg.logger.name == "none" else str(run_dir.path / "logs" / run_dir.path.name)
        )
        train_cfg = build_train_cfg(cfg, run_dir.path.name)
        run_dir.write_train_cfg(train_cfg)  # before the runner edits the dict in place
        with contextlib.redirect_stdout(io.StringIO()):  # rsl-rl prints the model summaries
            self.runner = OnPolicyRunner(self.env, train_cfg, log_dir=log_dir, device=self.device)
        self.alg = self.runner.alg
        self.runner.logger.git_status_repos = []  # provenance.json records the code state
        self.start = 0
        set_initial_stds(self.alg.get_policy(), cfg.actor, self.env.scene.joint_names)
        self.stats = EpisodeStats(self.env.num_envs, self.env.device)
        infos = self._load_newest_readable()
        if infos is None and cfg.algo.init_from:
            self._warm_start(Path(cfg.algo.init_from))
        self.rewards = RewardCurriculum(
            cfg.task.reward_curriculum, self.total, (infos or {}).get("penalty_scale")
        )
        self.commands = CommandCurriculum(cfg.task.command_curriculum, self.total)
        # the first iteration of the last phase (final_*): algo.final_from, else the
        # curriculum's end
        final_from = cfg.algo.final_from
        self.final_start = (
            math.ceil(final_from * self.total) if final_from >= 0 else self.rewards.end
        )
        self.stopped_early = False

    def levels_over(self, iteration: int) -> bool:
        """True from `terrain.levels_end` on, where the terrain-level curriculum is over."""
        return iteration >= self.cfg.terrain.levels_end * self.total

    def full_grid_from(self, iteration: int) -> bool:
        """True where `terrain.after_levels: full_grid` trains on the grid without levels."""
        t = self.cfg.terrain
        return bool(t.levels) and t.after_levels == "full_grid" and self.levels_over(iteration)

    def _match_terrain(self, iteration: int) -> bool:
        """Rebuild the env on the grid without levels once the terrain curriculum is over
        (`terrain.after_levels: full_grid`); True if it was rebuilt. Every episode restarts
        there: a new terrain is a new model."""
        if not self.full_grid_from(iteration) or self.env.terrain_levels is None:
            return False
        cfg = copy.deepcopy(self.cfg)
        cfg.terrain.levels = False
        with torch.random.fork_rng(devices=[]):  # the training's stream is the run's own
            self.env = LocomotionEnv(cfg)
        self.env.set_perception(self.perception_on(iteration))
        self.runner.env = self.env
        if self.alg.symmetry:  # rsl-rl hands the env to the mirror functions
            self.alg.symmetry.env = self.env
        self.stats = EpisodeStats(self.env.num_envs, self.env.device)
        print(f"[lca] it {iteration}: the terrain curriculum is over; training on the full grid")
        return True

    def perception_on(self, iteration: int) -> bool:
        return curriculum.perception_on(self.cfg.curriculum, iteration, self.total)

    def _set_update(self, it: int) -> None:
        """Critic warm-ups (after a warm start; after the reward curriculum ends): the
        actor's parameters out of the update and the learning rate held (no KL to adapt it
        to); at the end the configured rate is set again. From the curriculum's end (its
        cut or deadline; `algo.final_from` if set) with `final_learning_rate`, that rate,
        fixed."""
        a, end = self.cfg.algo, self.final_start
        frozen = it < a.critic_warmup or end <= it < end + a.final_critic_warmup
        actor = self.alg.actor
        was_frozen = not next(actor.parameters()).requires_grad
        if frozen != was_frozen:
            actor.requires_grad_(not frozen)
        if a.final_learning_rate > 0 and it >= end:
            self.alg.schedule = "fixed"
            set_learning_rate(self.alg, a.final_learning_rate)
        elif frozen != was_frozen:
            self.alg.schedule = "fixed" if frozen else a.schedule
            if not frozen:
                set_learning_rate(self.alg, a.learning_rate)

    def _curve_rows_before(self, iteration: int) -> list[dict]:
        """Curve rows of a resumed run up to its checkpoint (later rows are re-done)."""
        if iteration == 0 or not self.run.curve.exists():
            return []
        with self.run.curve.open(newline="") as f:
            return [r for r in csv.DictReader(f) if int(r["iteration"]) < iteration]

    def _check_finite(self, ends: np.ndarray, steps: int, it: int, streak: int) -> int:
        """Fail loudly, instead of finishing as COMPLETE, when the policy's output is never
        finite or when every episode of BROKEN_STREAK iterations in a row ends in a
        non-finite physics state. Returns the updated streak."""
        episodes, _, nonfinite, bad_actions = (int(x) for x in ends)
        if bad_actions == steps:
            raise RuntimeError(
                f"iteration {it}: every action of the policy was NaN or inf; the networks "
                "have diverged (lower algo.learning_rate, or check the observations)"
            )
        streak = streak + 1 if episodes > 0 and nonfinite == episodes else 0
        if streak >= min(BROKEN_STREAK, self.total):
            raise RuntimeError(
                f"iterations {it - streak + 1}-{it}: every episode ended in a non-finite "
                f"physics state ({nonfinite} of {episodes} in the last); the simulation is "
                "unstable (check sim.timestep, sim.decimation and the robot's gains)"
            )
        return streak

    def _rewrite_curve(self, rows: list[dict]) -> None:
        def write(tmp: str) -> None:
            with open(tmp, "w", newline="") as f:
                writer = csv.DictWriter(f, fieldnames=CURVE_FIELDS, extrasaction="ignore")
                writer.writeheader()
                writer.writerows(rows)

        write_atomically(self.run.curve, write)

    def train(self, hook=None) -> dict:
        """Train to `scale.max_iterations`. `hook(trainer, iteration, row)`, if given, runs
        after every iteration outside the timed training (its time is not in `wall_s`) and
        may return True to stop training there."""
        cfg, env, alg = self.cfg, self.env, self.alg
        num_steps = int(cfg.algo.num_steps_per_env)
        stats = self.stats
        alg.train_mode()
        switch = curriculum.switch_iteration(cfg.curriculum, self.total)
        kept = self._curve_rows_before(self.start)
        self.last = {k: _number(v) for k, v in kept[-1].items()} if kept else {}
        self._rewrite_curve(kept)  # atomically: the kept rows, or a fresh header
        curve = self.run.curve.open("a", newline="")
        writer = csv.DictWriter(curve, fieldnames=CURVE_FIELDS, extrasaction="ignore")
        env.set_perception(self.perception_on(self.start))
        obs = env.get_observations().to(self.device)
        t_start = time.perf_counter()
        try:
            self.runner.logger.init_logging_writer()
            with StopOnSignal() as self.stop:
                final = self._loop(writer, curve, stats, switch, obs, t_start, num_steps, hook)
            stage = curriculum.stage_name(cfg.curriculum, final, self.total)
            self.save(f"final_{stage}.pt", final, upload=True)
            self.save(LATEST, final)
        finally:
            curve.close()
            self.runner.logger.stop_logging_writer()  # wandb.finish() even on failure
        return self.last

    def _loop(self, writer, curve, stats, switch, obs, t_start, num_steps, hook) -> int:
        """Returns the index of the last iteration trained."""
        cfg, env, alg = self.cfg, self.env, self.alg
        paused = 0.0  # seconds spent in the hook, kept out of wall_s
        wall_before = float(self.last.get("wall_s", 0.0))  # a resumed run's earlier time
        broken_streak = 0
        actor = alg.get_policy()
        it = self.start - 1
        for it in range(self.start, self.total):
            if it == switch and it > 0 and not self.perception_on(it - 1):
                self.save(f"stage1_blind_it{it - 1}.pt", it - 1, upload=True)
            if self._match_terrain(it):
                env, stats = self.env, self.stats
                obs = env.get_observations().to(self.device)
            if self.perception_on(it) != env.perception:
                env.set_perception(self.perception_on(it))
                obs = env.get_observations().to(self.device)
            length = self.last.get("mean_episode_length", math.nan)
            progress = self.last.get("tracking_progress", math.nan)
            self.rewards.update(it, float(length) / env.max_episode_length, float(progress))
            env.reward_manager.set_shaping(*self.rewards.shaping)
            env.commands.min_speed = self.commands.floor(it)
            if env.terrain_levels is not None:
                env.terrain_levels.over = self.levels_over(it)
            if env.terrain_practice is not None:
                t = cfg.terrain
                on = t.practice_start * self.total <= it < t.practice_end * self.total
                env.terrain_practice.set(on)
            env.commands.ranges = self.commands.ranges(it, cfg.task.commands)
            ceiling = noise_ceiling(cfg.actor, it, self.total, self.rewards.progress)
            apply_ceiling(actor, ceiling)
            actor.kl_values = []
            # tallies stay in the env's array type until the iteration ends: no host sync per
            # step on a GPU. |u - v| and |u| over moving commands; episodes ended, falls,
            # non-finite, bad actions
            track_sums, ends = [0.0, 0.0], [0, 0, 0, 0]
            t0 = time.perf_counter()
            update_threads = torch.get_num_threads()
            if cfg.collect_threads > 0:
                torch.set_num_threads(int(cfg.collect_threads))
            with torch.inference_mode():
                for _ in range(num_steps):
                    actions = alg.act(obs)
                    obs, rewards, dones, extras = env.step(actions.to(env.device))
                    obs, rewards, dones = (
                        obs.to(self.device),
                        rewards.to(self.device),
                        dones.to(self.device),
                    )
                    alg.process_env_step(obs, rewards, dones, extras)
                    m = extras["metrics"]
                    counts = (dones, m["fell"], m["nonfinite"], m["nonfinite_action"])
                    ends = [total + count.sum() for total, count in zip(ends, counts, strict=True)]
                    moving = m["command_speed"] >= MOVING
                    track_sums = [
                        total + _masked_sum(m[key], moving)
                        for total, key in zip(track_sums, TRACKED, strict=True)
                    ]
                    self.runner.logger.process_env_step(rewards, dones, extras)
                    stats.add(rewards, dones, extras.get("log", {}))
                alg.compute_returns(obs)
            ends = np.array([int(v) for v in ends], dtype=np.int64)
            track_sums = np.array([float(v) for v in track_sums])
            torch.set_num_threads(update_threads)
            t1 = time.perf_counter()
            self._set_update(it)
            losses = alg.update()
            t2 = time.perf_counter()
            self.runner.current_learning_iteration = it
            with contextlib.redirect_stdout(io.StringIO()):
                self.runner.logger.log(
                    it=it,
                    start_it=self.start,
                    total_it=self.total,
                    collect_time=t1 - t0,
                    learn_time=t2 - t1,
                    loss_dict=losses,
                    learning_rate=alg.learning_rate,
                    action_std=alg.get_policy().output_std,
                    rnd_weight=None,
                )
            done_its = it + 1 - self.start
            elapsed = time.perf_counter() - t_start - paused
            kl = getattr(actor, "kl_values", [])
            x_range = env.commands.ranges.get("lin_vel_x", cfg.task.commands.lin_vel_x)
            row = {
                "iteration": it,
                "env_steps": (it + 1) * num_steps * env.num_envs,
                "wall_s": round(wall_before + elapsed, 3),
                "stage": "perception" if env.perception else "blind",
                "steps_per_s": num_steps * env.num_envs / (t2 - t0),
                "collect_s": t1 - t0,
                "update_s": t2 - t1,
                "value_loss": losses.get("value", losses.get("value_function", math.nan)),
                "surrogate_loss": losses.get("surrogate", math.nan),
                "action_std": float(actor.output_std.detach().mean()),
                "learning_rate": alg.learning_rate,
                "kl": float(np.mean(kl)) if kl else math.nan,
                "penalty_scale": self.rewards.scale,
                "command_floor": env.commands.min_speed,
                "command_x_low": x_range[0],
                "falls": int(ends[1]),
                "nonfinite": int(ends[2]),
                "nonfinite_actions": int(ends[3]),
                "terrain_level": env.terrain_levels.mean() if env.terrain_levels else math.nan,
                "tracking_progress": 1.0 - track_sums[0] / track_sums[1]
                if track_sums[1] > 0
                else math.nan,
                **stats.summary(),
            }
            writer.writerow(row)
            curve.flush()
            self.last = row
            broken_streak = self._check_finite(ends, num_steps * env.num_envs, it, broken_streak)
            if (it + 1) % cfg.scale.log_interval == 0 or it + 1 == self.total:
                eta = elapsed / done_its * (self.total - it - 1)
                print(
                    f"[lca] it {it + 1:>5}/{self.total} | {row['steps_per_s']:8,.0f} steps/s | "
                    f"reward {row['mean_reward']:8.2f} | ep len {row['mean_episode_length']:6.1f}"
                    f" | falls {row['falls']} | non-finite {row['nonfinite']}"
                    f" | {row['stage']:<10} | penalties x{row['penalty_scale']:.2f}"
                    f" | lr {row['learning_rate']:.1e} | ETA {_fmt_eta(eta)}",
                    flush=True,
                )
            if (it + 1) % cfg.scale.checkpoint_interval == 0 or self.stop.signum is not None:
                self.save(LATEST, it)
            exit_point("iteration", it)
            if self.stop.signum is not None:
                interrupted = TrainingInterrupted(self.stop.signum, it)
                print(f"[lca] {interrupted}", flush=True)  # SystemExit prints only its code
                raise interrupted
            if hook is not None:
                t_hook = time.perf_counter()
                stop = hook(self, it, row)
                paused += time.perf_counter() - t_hook
                if stop:
                    self.stopped_early = it + 1 < self.total
                    break
        return it

    def export(self) -> dict[str, Path]:
        """ONNX + TorchScript of the final actor; nothing for a kind that declares no export."""
        if not actor_spec(self.cfg.actor.kind).exports:
            return {}
        actor = self.alg.get_policy()
        return {
            "onnx": export_onnx(actor, self.run.exported / "policy.onnx"),
            "torchscript": export_jit(actor, self.run.exported / "policy.pt"),
        }
