"""One training run, top to bottom: env -> rsl-rl PPO -> curriculum -> checkpoints -> export.

The loop is rsl-rl's `OnPolicyRunner.learn` written out, so the curriculum can switch the
actor's perception at an exact iteration, a compact progress line can be printed, curves go
to CSV, and an interrupted run resumes from its last checkpoint. Scalars still go to
tensorboard / wandb through rsl-rl's own logger.
"""

from __future__ import annotations

import contextlib
import csv
import io
import math
import time
from collections import deque
from pathlib import Path

import numpy as np
import torch
from omegaconf import DictConfig
from rsl_rl.runners import OnPolicyRunner

from lca.config.runtime import resolve_device
from lca.learn import curriculum
from lca.learn.command_curriculum import CommandCurriculum
from lca.learn.exploration import apply_ceiling, noise_ceiling
from lca.learn.reward_curriculum import RewardCurriculum
from lca.learn.rundir import RunDir
from lca.learn.train_cfg import build_train_cfg
from lca.task.env import LocomotionEnv

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
)


class EpisodeStats:
    """Returns and lengths of finished episodes (last 100), and per-term episode sums."""

    def __init__(self, num_envs: int, device: torch.device):
        self.reward = torch.zeros(num_envs, device=device)
        self.length = torch.zeros(num_envs, device=device)
        self.returns: deque[float] = deque(maxlen=100)
        self.lengths: deque[float] = deque(maxlen=100)
        self.terms: dict[str, list[float]] = {}

    def add(self, rewards: torch.Tensor, dones: torch.Tensor, log: dict) -> None:
        self.reward += rewards
        self.length += 1
        done = dones > 0
        if done.any():
            self.returns.extend(self.reward[done].tolist())
            self.lengths.extend(self.length[done].tolist())
            self.reward[done] = 0
            self.length[done] = 0
        for key, value in log.items():
            if key.startswith("Episode_Reward/"):
                self.terms.setdefault(key.split("/", 1)[1], []).append(float(value))

    def summary(self) -> dict:
        out = {
            "mean_reward": float(np.mean(self.returns)) if self.returns else math.nan,
            "mean_episode_length": float(np.mean(self.lengths)) if self.lengths else math.nan,
        }
        for name in ("track_lin_vel_xy_exp", "track_ang_vel_z_exp"):
            values = self.terms.get(name)
            out[name] = float(np.mean(values)) if values else math.nan
        self.terms.clear()
        return out


def _number(text: str):
    try:
        return float(text)
    except ValueError:
        return text


def _fmt_eta(seconds: float) -> str:
    seconds = int(max(seconds, 0))
    return f"{seconds // 3600:d}:{seconds % 3600 // 60:02d}:{seconds % 60:02d}"


class Trainer:
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
        with contextlib.redirect_stdout(io.StringIO()):  # rsl-rl prints the model summaries
            self.runner = OnPolicyRunner(self.env, train_cfg, log_dir=log_dir, device=self.device)
        self.alg = self.runner.alg
        self.start = 0
        infos = None
        latest = run_dir.latest_checkpoint()
        if latest is not None:
            infos = self.runner.load(str(latest), map_location=self.device)
            # rsl-rl stores the index of the last finished iteration
            self.start = self.runner.current_learning_iteration + 1
            print(f"[lca] resuming {run_dir.path.name} at iteration {self.start}/{self.total}")
        self.rewards = RewardCurriculum(
            cfg.task.reward_curriculum, self.total, (infos or {}).get("penalty_scale")
        )
        self.commands = CommandCurriculum(cfg.task.command_curriculum, self.total)
        self.stopped_early = False

    def perception_on(self, iteration: int) -> bool:
        return curriculum.perception_on(self.cfg.curriculum, iteration, self.total)

    def save(self, name: str, iteration: int) -> Path:
        self.run.checkpoints.mkdir(parents=True, exist_ok=True)
        self.runner.current_learning_iteration = iteration
        path = self.run.checkpoints / name
        tmp = path.with_suffix(".tmp")
        self.runner.save(
            str(tmp),
            infos={
                "stage": curriculum.stage_name(self.cfg.curriculum, iteration, self.total),
                "penalty_scale": self.rewards.scale,
            },
        )
        tmp.replace(path)
        return path

    def _curve_rows_before(self, iteration: int) -> list[dict]:
        """Curve rows of a resumed run up to its checkpoint (later rows are re-done)."""
        if iteration == 0 or not self.run.curve.exists():
            return []
        with self.run.curve.open(newline="") as f:
            return [r for r in csv.DictReader(f) if int(r["iteration"]) < iteration]

    def train(self, hook=None) -> dict:
        """Train to `scale.max_iterations`. `hook(trainer, iteration, row)`, if given, runs
        after every iteration outside the timed training (its time is not in `wall_s`) and
        may return True to stop training there."""
        cfg, env, alg = self.cfg, self.env, self.alg
        num_steps = int(cfg.algo.num_steps_per_env)
        stats = EpisodeStats(env.num_envs, env.device)
        alg.train_mode()
        switch = curriculum.switch_iteration(cfg.curriculum, self.total)
        kept = self._curve_rows_before(self.start)
        self.last = {k: _number(v) for k, v in kept[-1].items()} if kept else {}
        curve = self.run.curve.open("w", newline="")
        writer = csv.DictWriter(curve, fieldnames=CURVE_FIELDS)
        writer.writeheader()
        writer.writerows(kept)
        env.set_perception(self.perception_on(self.start))
        obs = env.get_observations().to(self.device)
        t_start = time.perf_counter()
        try:
            self.runner.logger.init_logging_writer()
            final = self._loop(writer, curve, stats, switch, obs, t_start, num_steps, hook)
            stage = curriculum.stage_name(cfg.curriculum, final, self.total)
            self.save(f"final_{stage}.pt", final)
            self.save("latest.pt", final)
        finally:
            curve.close()
            self.runner.logger.stop_logging_writer()  # wandb.finish() even on failure
        return self.last

    def _loop(self, writer, curve, stats, switch, obs, t_start, num_steps, hook) -> int:
        """Returns the index of the last iteration trained."""
        cfg, env, alg = self.cfg, self.env, self.alg
        paused = 0.0  # seconds spent in the hook, kept out of wall_s
        wall_before = float(self.last.get("wall_s", 0.0))  # a resumed run's earlier time
        actor = alg.get_policy()
        it = self.start - 1
        for it in range(self.start, self.total):
            if it == switch and it > 0 and not self.perception_on(it - 1):
                self.save(f"stage1_blind_it{it - 1}.pt", it - 1)
            if self.perception_on(it) != env.perception:
                env.set_perception(self.perception_on(it))
                obs = env.get_observations().to(self.device)
            length = self.last.get("mean_episode_length", math.nan)
            self.rewards.update(it, float(length) / env.max_episode_length)
            env.set_reward_shaping(self.rewards.scale, self.rewards.only_positive)
            env.commands.min_speed = self.commands.floor(it)
            apply_ceiling(actor, noise_ceiling(cfg.actor, it, self.total))
            actor.kl_values = []
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
                    self.runner.logger.process_env_step(rewards, dones, extras)
                    stats.add(rewards, dones, extras.get("log", {}))
                alg.compute_returns(obs)
            torch.set_num_threads(update_threads)
            t1 = time.perf_counter()
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
                **stats.summary(),
            }
            writer.writerow(row)
            curve.flush()
            self.last = row
            if (it + 1) % cfg.scale.log_interval == 0 or it + 1 == self.total:
                eta = elapsed / done_its * (self.total - it - 1)
                print(
                    f"[lca] it {it + 1:>5}/{self.total} | {row['steps_per_s']:8,.0f} steps/s | "
                    f"reward {row['mean_reward']:8.2f} | ep len {row['mean_episode_length']:6.1f}"
                    f" | {row['stage']:<10} | penalties x{row['penalty_scale']:.2f}"
                    f" | lr {row['learning_rate']:.1e} | ETA {_fmt_eta(eta)}",
                    flush=True,
                )
            if (it + 1) % cfg.scale.checkpoint_interval == 0:
                self.save("latest.pt", it)
            if hook is not None:
                t_hook = time.perf_counter()
                stop = hook(self, it, row)
                paused += time.perf_counter() - t_hook
                if stop:
                    self.stopped_early = it + 1 < self.total
                    break
        return it

    def export(self) -> dict[str, Path]:
        self.run.exported.mkdir(parents=True, exist_ok=True)
        with contextlib.redirect_stdout(io.StringIO()), warnings_quiet():
            self.runner.export_policy_to_onnx(str(self.run.exported), "policy.onnx")
            self.runner.export_policy_to_jit(str(self.run.exported), "policy.pt")
        return {
            "onnx": self.run.exported / "policy.onnx",
            "torchscript": self.run.exported / "policy.pt",
        }


@contextlib.contextmanager
def warnings_quiet():
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        yield
