"""Returns and lengths of the episodes that finished during training."""

from __future__ import annotations

import math
from collections import deque

import numpy as np
import torch


class EpisodeStats:
    """Returns and lengths of finished episodes (last 100), and per-term episode sums."""

    def __init__(self, num_envs: int, device: torch.device):
        self.reward = torch.zeros(num_envs, device=device)
        self.length = torch.zeros(num_envs, device=device)
        self.returns: deque[float] = deque(maxlen=100)
        self.lengths: deque[float] = deque(maxlen=100)
        self.terms: dict[str, list] = {}  # per-term episode means (floats or 0-d arrays)
        self._steps: list[tuple[torch.Tensor, torch.Tensor, torch.Tensor]] = []

    def add(self, rewards: torch.Tensor, dones: torch.Tensor, log: dict) -> None:
        """One step. Finished episodes are gathered by `flush`, once per iteration, so that a
        step needs no host sync on a GPU."""
        self.reward += rewards
        self.length += 1
        done = dones > 0
        self._steps.append((done, self.reward.clone(), self.length.clone()))
        self.reward.masked_fill_(done, 0)
        self.length.masked_fill_(done, 0)
        for key, value in log.items():
            if key.startswith("Episode_Reward/"):
                self.terms.setdefault(key.split("/", 1)[1], []).append(value)

    def flush(self) -> None:
        """The episodes that finished in the steps since the last flush, in step order."""
        if not self._steps:
            return
        done, reward, length = (torch.stack(parts) for parts in zip(*self._steps, strict=True))
        self.returns.extend(reward[done].tolist())
        self.lengths.extend(length[done].tolist())
        self._steps.clear()

    def summary(self) -> dict:
        self.flush()
        out = {
            "mean_reward": float(np.mean(self.returns)) if self.returns else math.nan,
            "mean_episode_length": float(np.mean(self.lengths)) if self.lengths else math.nan,
        }
        for name in ("track_lin_vel_xy_exp", "track_ang_vel_z_exp"):
            values = self.terms.get(name)
            out[name] = float(np.mean([float(v) for v in values])) if values else math.nan
        self.terms.clear()
        return out

    def state_dict(self) -> dict:
        self.flush()
        return {
            "reward": self.reward.clone(),
            "length": self.length.clone(),
            "returns": list(self.returns),
            "lengths": list(self.lengths),
        }

    def load_state_dict(self, state: dict) -> None:
        self.reward[:] = state["reward"].to(self.reward.device)
        self.length[:] = state["length"].to(self.length.device)
        self.returns.clear()
        self.returns.extend(state["returns"])
        self.lengths.clear()
        self.lengths.extend(state["lengths"])
