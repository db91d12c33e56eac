"""The env's reward: the paper's weighted terms under the reward curriculum's knobs, summed
per episode for the logs (mjlab's reward manager, in small)."""

from __future__ import annotations

import copy

from lca.arrays import Array, namespace, zeros
from lca.config.registry import REWARD_TERMS
from lca.task.config import TaskConfig
from lca.task.rewards import RewardContext, compute_rewards, weights_and_params


class RewardManager:
    def __init__(self, task: TaskConfig, num_envs: int, ref: Array):
        self.task_params = task.reward_params
        self.weights, self.term_params = weights_and_params(task.rewards)
        self.fns = {name: REWARD_TERMS[name] for name in self.weights}
        self._stateful_resets = [
            f.reset for f in self.fns.values() if callable(getattr(f, "reset", None))
        ]
        # the reward curriculum's knobs (lca.learn.reward_curriculum); the paper's: 1, {}, 1
        self.penalty_scale, self.boosts = 1.0, {}
        self.sigma_scale, self.params = 1.0, task.reward_params
        self.always_positive = bool(task.only_positive_rewards)
        self.only_positive = self.always_positive
        self.scaled_terms = frozenset(task.reward_curriculum.terms) or None
        self.unclipped = frozenset(task.reward_curriculum.unclipped)
        self.xp = namespace(ref)
        self.episode_sums: dict[str, Array] = {k: zeros(num_envs, ref) for k in self.weights}

    def set_shaping(
        self,
        penalty_scale: float,
        only_positive: bool,
        boosts: dict | None = None,
        sigma_scale: float = 1.0,
    ) -> None:
        """Penalties x `penalty_scale`, boosted weights, clipping, the tracking kernels'
        sigma x `sigma_scale`."""
        self.penalty_scale = float(penalty_scale)
        self.boosts = dict(boosts or {})
        if float(sigma_scale) != self.sigma_scale:
            self.sigma_scale = float(sigma_scale)
            self.params = copy.deepcopy(self.task_params)
            self.params.tracking_sigma *= self.sigma_scale
        self.only_positive = bool(only_positive) or self.always_positive

    def compute(self, ctx: RewardContext, dt: float) -> Array:
        """The step's reward, (N,); each weighted term is added to its episode sum."""
        reward, terms = compute_rewards(
            ctx,
            self.weights,
            dt,
            only_positive=self.only_positive,
            penalty_scale=self.penalty_scale,
            scaled_terms=self.scaled_terms,
            unclipped=self.unclipped,
            params=self.term_params,
            boosts=self.boosts,
            fns=self.fns,
        )
        for name, value in terms.items():
            self.episode_sums[name] += value
        return reward

    def reset(self, ids: Array) -> None:
        for sums in self.episode_sums.values():
            sums[ids] = 0.0
        for reset in self._stateful_resets:  # reward terms that keep per-env state
            reset(ids)

    def episode_log(self, ids: Array) -> dict:
        """The mean of each term's episode sum over the episodes `ids` that just ended."""
        mean = self.xp.mean
        return {f"Episode_Reward/{k}": mean(sums[ids]) for k, sums in self.episode_sums.items()}

    def curriculum_log(self) -> dict:
        log = {
            "Curriculum/penalty_scale": self.penalty_scale,
            "Curriculum/only_positive": float(self.only_positive),
        }
        log |= {f"Curriculum/boost_{name}": factor for name, factor in self.boosts.items()}
        if self.sigma_scale != 1.0:
            log["Curriculum/sigma_scale"] = self.sigma_scale
        return log
