"""rsl-rl's symmetry augmentation for the G1: every mini-batch also holds its mirror image.

`algo.symmetry=true` puts `augment` into rsl-rl's `symmetry_cfg`; the task layer defines the
mirror itself (`lca.task.symmetry`).
"""

from __future__ import annotations

import torch
from tensordict import TensorDict

from lca.task import symmetry

FLAT_GROUPS = ("policy", "critic")
MAP_GROUPS = ("height", "critic_height")


def _mirrors(env) -> dict[str, tuple[torch.Tensor, torch.Tensor]]:
    cached = getattr(env, "_torch_mirrors", None)
    if cached is None:
        maps = symmetry.proprioception_mirrors(env.scene.joint_names, env.task_cfg.observations)
        cached = {
            k: (
                torch.as_tensor(m.perm, device=env.device),
                torch.as_tensor(m.sign, dtype=torch.float32, device=env.device),
            )
            for k, m in maps.items()
        }
        env._torch_mirrors = cached
    return cached


def _apply(x: torch.Tensor, perm_sign: tuple[torch.Tensor, torch.Tensor]) -> torch.Tensor:
    perm, sign = perm_sign
    return x[..., perm.to(x.device)] * sign.to(x.device)


def mirror_observations(env, obs: TensorDict) -> TensorDict:
    maps = _mirrors(env)
    mirrored = obs.clone()
    for group in obs.keys():  # noqa: SIM118 (iterating a TensorDict yields rows)
        if group in FLAT_GROUPS:
            mirrored[group] = _apply(obs[group], maps[group])
        elif group in MAP_GROUPS:
            mirrored[group] = torch.flip(obs[group], dims=[-1])
    return mirrored


def mirror_actions(env, actions: torch.Tensor) -> torch.Tensor:
    return _apply(actions, _mirrors(env)["actions"])


def augment(env, obs: TensorDict | None = None, actions: torch.Tensor | None = None):
    """rsl-rl's `data_augmentation_func`: originals first, then their mirror images."""
    if obs is not None:
        obs = torch.cat([obs, mirror_observations(env, obs)], dim=0)
    if actions is not None:
        actions = torch.cat([actions, mirror_actions(env, actions)], dim=0)
    return obs, actions
