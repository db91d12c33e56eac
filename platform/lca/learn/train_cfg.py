"""The rsl-rl-lib `train_cfg` dict for a composed config (a fresh plain dict every call:
the runner edits it in place)."""

from __future__ import annotations

import os

from omegaconf import DictConfig, OmegaConf

from lca.learn.variants import actor_spec

CRITIC_CLASS = "lca.learn.models:PerceptiveMLPModel"
SYMMETRY_FUNC = "lca.learn.symmetry:augment"
OBS_GROUPS = {"actor": ["policy", "height"], "critic": ["critic", "critic_height"]}


def encoder_cfg(cfg: DictConfig) -> dict:
    enc = OmegaConf.to_container(cfg.encoder, resolve=True)
    enc.pop("name")
    return enc


def logger_cfg(cfg: DictConfig) -> str | dict | None:
    if cfg.logger.name == "wandb":
        os.environ.setdefault("WANDB_MODE", cfg.logger.wandb_mode)
        return {"class_name": "WandbLogWriter", "project_name": cfg.logger.wandb_project}
    return "tensorboard"


def build_train_cfg(cfg: DictConfig, run_name: str) -> dict:
    algo = OmegaConf.to_container(cfg.algo, resolve=True)
    algo.pop("name")
    num_steps = algo.pop("num_steps_per_env")
    # read by the trainer, not by PPO
    for key in (
        "init_from",
        "init_map_zero",
        "init_widen_history",
        "critic_warmup",
        "final_learning_rate",
        "final_critic_warmup",
        "final_from",
    ):
        algo.pop(key)
    obs_normalization = algo.pop("obs_normalization")
    symmetry_cfg = None
    mirror_loss = algo.pop("mirror_loss_coeff")
    # rsl-rl's symmetry extension takes feed-forward actors only; recurrent ones train without
    spec = actor_spec(cfg.actor.kind)
    recurrent = spec.recurrent
    if (algo.pop("symmetry") or mirror_loss > 0) and not recurrent:
        symmetry_cfg = {
            "use_data_augmentation": bool(cfg.algo.symmetry),
            "use_mirror_loss": mirror_loss > 0,
            "mirror_loss_coeff": mirror_loss,
            "data_augmentation_func": SYMMETRY_FUNC,
        }
    actor = {
        "class_name": spec.class_path,
        "hidden_dims": list(cfg.actor.hidden_dims),
        "activation": cfg.actor.activation,
        "obs_normalization": obs_normalization,
        "encoder_cfg": encoder_cfg(cfg),
        "distribution_cfg": {
            "class_name": "GaussianDistribution",
            "init_std": cfg.actor.init_noise_std,
            "std_type": "scalar",
        },
    }
    actor |= spec.model_kwargs
    if recurrent:
        actor["rnn_hidden_dim"] = cfg.actor.rnn_hidden_dim
    critic = {
        "class_name": CRITIC_CLASS,
        "hidden_dims": list(cfg.actor.hidden_dims),  # paper: the critic has the actor's sizes
        "activation": cfg.actor.activation,
        "obs_normalization": obs_normalization,
        "encoder_cfg": encoder_cfg(cfg),
    }
    return {
        "num_steps_per_env": num_steps,
        "save_interval": 10**9,  # checkpoints are written by lca's trainer, not the runner
        "obs_groups": {k: list(v) for k, v in OBS_GROUPS.items()},
        "algorithm": {"class_name": "PPO", **algo, "rnd_cfg": None, "symmetry_cfg": symmetry_cfg},
        "actor": actor,
        "critic": critic,
        "logger": logger_cfg(cfg),
        "run_name": run_name,
        "check_for_nan": True,
    }
