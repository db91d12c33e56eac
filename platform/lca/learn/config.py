"""Config groups of the learning stage: actor, encoder, curriculum, PPO, logger, scale."""

from __future__ import annotations

from dataclasses import dataclass, field

from lca.config.errors import require
from lca.config.registry import ACTORS, ENCODERS
from lca.config.schema import group


@group("actor")
@dataclass
class ActorConfig:
    name: str = "mlp"
    kind: str = "mlp"  # a registered actor kind (lca.learn.variants): mlp | lstm
    hidden_dims: list[int] = field(default_factory=lambda: [512, 256, 128])  # paper, ELU
    activation: str = "elu"
    rnn_hidden_dim: int = 256  # LSTM width before the MLP head (lstm only)
    init_noise_std: float = 1.0
    # joint group (legs, waist, arms) or joint name regex -> initial action std of its joints
    # (first match wins); e.g. a quiet upper body while the legs explore
    init_noise_std_joints: dict[str, float] = field(default_factory=dict)
    # > 0: the action std is capped by a ceiling falling linearly from init_noise_std to this
    # value at `noise_deadline` x max_iterations (and staying there): explore early, act
    # precisely once the penalties are the paper's. 0: rsl-rl's free, learned std.
    final_noise_std: float = 0.0
    noise_deadline: float = 0.6
    noise_start: float = 0.0  # iterations: the ceiling stays at init_noise_std until here
    # what lowers the ceiling: the iteration (to noise_deadline) or the reward curriculum's
    # progress (the ceiling reaches final_noise_std as the penalties reach the paper's)
    noise_by: str = "iterations"

    def check(self) -> None:
        ACTORS.check(self.kind, "actor.kind")
        require(self.init_noise_std > 0, "actor.init_noise_std", "must be > 0")
        require(
            0 <= self.final_noise_std <= self.init_noise_std,
            "actor.final_noise_std",
            f"must be in [0, init_noise_std={self.init_noise_std}], got {self.final_noise_std}",
        )
        require(0 <= self.noise_deadline <= 1, "actor.noise_deadline", "must be in [0, 1]")
        require(
            0 <= self.noise_start < max(self.noise_deadline, 1e-9) or self.noise_start == 0,
            "actor.noise_start",
            f"need 0 <= noise_start < noise_deadline, got {self.noise_start}",
        )
        allowed = ("iterations", "penalties")
        require(self.noise_by in allowed, "actor.noise_by", f"allowed: {allowed}")


@group("encoder")
@dataclass
class EncoderConfig:
    name: str = "cnn"
    kind: str = "cnn"  # a registered encoder kind (lca.learn.variants): cnn | mlp
    # paper: CNN (3x3, stride 1) with hidden {256, 256}
    hidden_dims: list[int] = field(default_factory=lambda: [256, 256])
    latent_dim: int = 32  # z_H; the paper leaves d_H open
    # two 3x3 stride-1 convolutions ahead of the {256, 256} head (cnn only)
    conv_channels: list[int] = field(default_factory=lambda: [8, 16])
    kernel_size: int = 3
    stride: int = 1
    # max-pool after each convolution (cnn only); 0: none, the paper's CNN. 2: 11x11 -> 5x5 ->
    # 2x2, ~5x cheaper updates on CPU; tables label such rows "CNN (pooled)"
    pool: int = 0

    def check(self) -> None:
        ENCODERS.check(self.kind, "encoder.kind")
        require(self.pool in (0, 2, 3), "encoder.pool", f"allowed: 0 (none), 2, 3; got {self.pool}")


@group("curriculum")
@dataclass
class CurriculumConfig:
    name: str = "two"
    # fraction of iterations after which the actor sees its map (paper: blind for the first
    # half, then perception on)
    perception_from: float = 0.5

    def check(self) -> None:
        require(
            0.0 <= self.perception_from <= 1.0, "curriculum.perception_from", "must be in [0, 1]"
        )


@group("algo")
@dataclass
class AlgoConfig:
    """rsl-rl-lib PPO with an asymmetric critic; legged-gym / IsaacLab defaults."""

    name: str = "ppo"
    num_steps_per_env: int = 24
    num_learning_epochs: int = 5
    num_mini_batches: int = 4
    clip_param: float = 0.2
    gamma: float = 0.99
    lam: float = 0.95
    value_loss_coef: float = 1.0
    entropy_coef: float = 0.005
    learning_rate: float = 1.0e-3
    max_grad_norm: float = 1.0
    schedule: str = "adaptive"
    desired_kl: float = 0.01
    obs_normalization: bool = True  # proprioception only; heightmaps bypass the normaliser
    symmetry: bool = False  # rsl-rl symmetry_cfg: every mini-batch also holds its mirror image
    mirror_loss_coeff: float = 0.0  # > 0 adds rsl-rl's mirror loss (MLP actors only)
    # a checkpoint whose actor and critic start this run (a warm start): its optimizer and
    # iteration are not loaded, so every schedule starts at iteration 0. "": from scratch
    init_from: str = ""
    # with init_from: the map contributes nothing at first (lca.learn.warm_start): a blind
    # MLP-encoder source's zero-map features folded into the first layer's bias, their weights
    # zero, the encoder fresh; any encoder (mlp, cnn) can start so. false: a strict load
    init_map_zero: bool = False
    # with init_from: a source trained with a shorter task.observations.history starts this
    # run's longer one (lca.learn.warm_start): the older frames' weights zero, so it acts as
    # the source at first. false: the history lengths must match
    init_widen_history: bool = False
    # iterations at the start that train the critic only (the actor frozen, the learning rate
    # fixed): a warm start's critic first learns the new run's returns. 0: none
    critic_warmup: int = 0
    # from the reward curriculum's end (its cut or deadline: the table's weights, unclipped)
    # PPO's learning rate is fixed at this (0: the schedule goes on), so the gait shaped
    # before is changed slowly; the first `final_critic_warmup` iterations from there train
    # the critic alone on the new returns
    final_learning_rate: float = 0.0
    final_critic_warmup: int = 0
    # fraction of the run from which the two above apply instead of the curriculum's end
    # (-1: that end), e.g. a last phase that starts after a spell on the table's weights
    final_from: float = -1.0

    def check(self) -> None:
        def positive(key: str) -> None:
            value = getattr(self, key)
            require(value > 0, f"algo.{key}", f"must be > 0, got {value}")

        def at_least_one(key: str) -> None:
            value = getattr(self, key)
            require(value >= 1, f"algo.{key}", f"must be >= 1, got {value}")

        for key in ("learning_rate", "clip_param", "max_grad_norm", "desired_kl"):
            positive(key)
        require(self.critic_warmup >= 0, "algo.critic_warmup", "must be >= 0")
        require(self.final_critic_warmup >= 0, "algo.final_critic_warmup", "must be >= 0")
        require(self.final_learning_rate >= 0, "algo.final_learning_rate", "must be >= 0")
        require(
            self.final_from == -1.0 or 0 <= self.final_from <= 1,
            "algo.final_from",
            f"must be in [0, 1] or -1 (the curriculum's end), got {self.final_from}",
        )
        for key in ("num_steps_per_env", "num_learning_epochs", "num_mini_batches"):
            at_least_one(key)
        for key in ("entropy_coef", "value_loss_coef", "mirror_loss_coeff"):
            value = getattr(self, key)
            require(value >= 0, f"algo.{key}", f"must be >= 0, got {value}")
        require(0 < self.gamma <= 1, "algo.gamma", f"must be in (0, 1], got {self.gamma}")
        require(0 <= self.lam <= 1, "algo.lam", f"must be in [0, 1], got {self.lam}")
        allowed = ("adaptive", "fixed")
        require(
            self.schedule in allowed,
            "algo.schedule",
            f"unknown '{self.schedule}'; allowed: {allowed}",
        )


@group("logger")
@dataclass
class LoggerConfig:
    name: str = "tensorboard"  # tensorboard | wandb | none
    wandb_project: str = "lca"
    wandb_mode: str = "offline"  # used unless WANDB_MODE is set in the environment

    def check(self) -> None:
        allowed = ("tensorboard", "wandb", "none")
        require(self.name in allowed, "logger.name", f"unknown '{self.name}'; allowed: {allowed}")


@group("scale")
@dataclass
class ScaleConfig:
    name: str = "cpu"
    max_iterations: int = 30
    log_interval: int = 5  # iterations between progress lines
    checkpoint_interval: int = 10  # iterations between resumable checkpoints

    def check(self) -> None:
        for key in ("max_iterations", "log_interval", "checkpoint_interval"):
            value = getattr(self, key)
            require(value >= 1, f"scale.{key}", f"must be >= 1, got {value}")
