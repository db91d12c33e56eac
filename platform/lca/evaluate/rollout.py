"""The one rollout loop every test of a trained policy uses: evaluation rounds, hardware-style
trials and the training probes. A recurrent policy's state restarts with each episode."""

from __future__ import annotations

import itertools
from collections.abc import Iterator

import numpy as np
import torch
from tensordict import TensorDict

from lca.arrays import to_numpy
from lca.task.env import LocomotionEnv


def start(env: LocomotionEnv, policy) -> TensorDict:
    """Every unit reset (and the policy's memory with it); the first observations. A test
    of a policy reads the actor's observations only: the env stops building the critic's."""
    env.observe_critic = False
    obs = env.reset_all()
    policy.reset(torch.ones(env.num_envs, dtype=torch.bool, device=env.device))
    return obs


def step_only(env: LocomotionEnv, units: np.ndarray) -> None:
    """From the next step on, the physics steps only the units where `units` (bool, one per
    unit) holds; the others stand frozen. A test stops counting a unit at its first
    termination, and simulating it further was most of a failing policy's cost. Their
    observations and rewards are still computed (vectorised, cheap) and ignored. A backend
    that steps every world at once (warp) keeps stepping them all."""
    if env.sim.steps_subsets:
        env.stepping = np.flatnonzero(units)


def rollout(
    env: LocomotionEnv, policy, obs: TensorDict, steps: int | None
) -> Iterator[tuple[int, dict]]:
    """Up to `steps` policy steps from `obs` (None: until the caller stops), yielding
    (step, the env's per-unit metrics); the caller stops early by leaving the loop."""
    for step in range(steps) if steps is not None else itertools.count():
        with torch.inference_mode():
            obs, _, dones, extras = env.step(policy(obs))
        # NumPy for the protocol's bookkeeping, whatever the physics' arrays are
        yield step, {name: to_numpy(value) for name, value in extras["metrics"].items()}
        policy.reset(dones.bool())
