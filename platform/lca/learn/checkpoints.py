"""Checkpoints of a training run: written atomically, read back for an exact resume (networks,
optimizer, environment, RNG and recurrent states), or for a warm start (networks only).

A mixin of `Trainer`: it uses the trainer's run directory, runner, algorithm, environment,
episode statistics, curricula and config.
"""

from __future__ import annotations

import os
from pathlib import Path

import torch

from lca.learn import curriculum
from lca.learn.warm_start import widen_history, zero_map_state
from lca.paths import root
from lca.store import write_atomically
from lca.task.env_state import env_state, restore_env_state

LATEST, PREVIOUS = "latest.pt", "previous.pt"
LOOP_STATE = "lca_loop_state"  # env, episode statistics, RNG and recurrent states


def set_learning_rate(alg, rate: float) -> None:
    """PPO's learning rate: the adaptive schedule's value and the optimizer's groups."""
    alg.learning_rate = float(rate)
    for group in alg.optimizer.param_groups:
        group["lr"] = alg.learning_rate


def _clone(hidden):
    if hidden is None:
        return None
    return tuple(h.clone() for h in hidden) if isinstance(hidden, tuple) else hidden.clone()


class Checkpoints:
    def save(self, name: str, iteration: int, upload: bool = False) -> Path:
        """Write checkpoints/<name> atomically (a uniquely named temporary file, then a
        rename). `latest.pt`'s previous version is kept as `previous.pt`, the fallback of a
        resume. `upload` registers the final path with the logger (wandb)."""
        self.runner.current_learning_iteration = iteration
        saved = self.alg.save()
        saved["iter"] = iteration
        saved["infos"] = {
            "stage": curriculum.stage_name(self.cfg.curriculum, iteration, self.total),
            "penalty_scale": self.rewards.scale,
        }
        saved[LOOP_STATE] = self._loop_state()
        path = self.run.checkpoints / name

        def write(tmp: str) -> None:
            torch.save(saved, tmp)
            if name == LATEST and path.exists():  # rotated only once the new one is written
                os.replace(path, self.run.checkpoints / PREVIOUS)

        write_atomically(path, write)
        if upload:
            self.runner.logger.save_model(str(path), iteration)
        return path

    def _loop_state(self) -> dict:
        """What the loop carries across an iteration boundary besides the networks, so a
        resumed run continues exactly as the uninterrupted one would."""
        hidden = {}
        for name in ("actor", "critic"):
            model = getattr(self.alg, name)
            if model.is_recurrent:
                hidden[name] = _clone(model.rnn.hidden_state)
        return {
            "env": env_state(self.env),
            "stats": self.stats.state_dict(),
            "torch_rng": torch.get_rng_state(),
            "cuda_rng": torch.cuda.get_rng_state_all() if torch.cuda.is_available() else None,
            "hidden": hidden,
        }

    def _restore_loop_state(self, saved: dict, path: Path) -> None:
        state = saved.get(LOOP_STATE)
        if state is None:  # a shipped checkpoint, or one from before exact resume
            print(f"[lca] {path.name} holds no loop state: the environment starts afresh")
            return
        # the state is of the env that trained the saved iteration: past the terrain's rebuild,
        # the full grid (a rebuild due at `start` itself happens in the loop, as it did)
        self._match_terrain(self.start - 1)
        restore_env_state(self.env, state["env"])
        self.stats.load_state_dict(state["stats"])
        torch.set_rng_state(state["torch_rng"].cpu())
        if state["cuda_rng"] is not None and torch.cuda.is_available():
            torch.cuda.set_rng_state_all(state["cuda_rng"])
        for name, hidden in state["hidden"].items():
            getattr(self.alg, name).rnn.hidden_state = hidden

    def _warm_start(self, path: Path) -> None:
        """Networks (and their observation normalisers and action std) from `path`; the
        optimizer, iteration and every schedule start afresh."""
        if not path.is_absolute() and not path.exists():  # a path inside the checkout
            path = root() / path
        if not path.is_file():
            raise FileNotFoundError(f"algo.init_from: no checkpoint at {path}")
        algo = self.cfg.algo
        if not algo.init_map_zero and not algo.init_widen_history:
            self.runner.load(
                str(path), load_cfg={"actor": True, "critic": True}, map_location=self.device
            )
            print(f"[lca] {self.run.path.name} starts from the networks of {path}")
            return
        saved = torch.load(path, map_location=self.device, weights_only=False)
        frames, frame_dim = self.env.history.buffer.shape[1:]
        for name in ("actor", "critic"):
            model = getattr(self.alg, name)
            source = saved[f"{name}_state_dict"]
            if algo.init_widen_history:
                source = widen_history(source, model, frame_dim, frames)
            if algo.init_map_zero:
                source = zero_map_state(source, model, self.cfg.actor.activation)
            model.load_state_dict(source)
        how = ["its map's contribution zero"] if algo.init_map_zero else []
        if algo.init_widen_history:
            how.append(f"its history widened to {frames} frames")
        print(f"[lca] {self.run.path.name} starts from the networks of {path}, {', '.join(how)}")

    def _load_newest_readable(self) -> dict | None:
        """Load the newest checkpoint that reads (latest, then previous), saying what was
        skipped and why; None when there is none. Raises naming the files if none reads."""
        candidates = [p for p in (LATEST, PREVIOUS) if (self.run.checkpoints / p).exists()]
        errors = []
        for name in candidates:
            path = self.run.checkpoints / name
            try:
                # a shipped checkpoint holds the networks only: its optimizer starts afresh
                saved = torch.load(path, map_location=self.device, weights_only=False)
                parts = {"actor": True, "critic": True, "iteration": True}
                parts["optimizer"] = "optimizer_state_dict" in saved
                self.alg.load(saved, parts, strict=True)
            except Exception as error:  # a truncated or corrupt file
                reason = str(error).splitlines()[0][:200]
                print(f"[lca] skipping unreadable checkpoint {path}: {reason}")
                errors.append(f"{path}: {reason}")
                continue
            rate = (saved.get("infos") or {}).get("learning_rate")
            if not parts["optimizer"] and rate is not None:  # a fresh Adam at the run's rate
                set_learning_rate(self.alg, rate)
            # rsl-rl stores the index of the last finished iteration
            self.runner.current_learning_iteration = int(saved["iter"])
            self.start = self.runner.current_learning_iteration + 1
            self._restore_loop_state(saved, path)
            exact = parts["optimizer"] and saved.get(LOOP_STATE) is not None
            self.run.record_resume(self.start, name, exact)
            print(
                f"[lca] resuming {self.run.path.name} at iteration {self.start}/{self.total}"
                f" (from {name})"
            )
            return saved.get("infos") or {}
        if errors:
            raise RuntimeError(
                "no readable checkpoint to resume from: "
                + "; ".join(errors)
                + f". Delete {self.run.checkpoints} to start this run afresh (or force=true)."
            )
        return None
