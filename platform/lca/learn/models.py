"""Actor and critic as rsl-rl-lib model classes (resolved by class name by the runner).

    actor:  encoder(heightmap) -> z ; [normalised proprioception, z] -> MLP or LSTM->MLP -> a
    critic: encoder(privileged map) -> z ; [normalised privileged state, z] -> MLP -> V

Heightmaps bypass rsl-rl's empirical normaliser: a map that is all zeros during a blind stage
would get zero variance and be blown up ~100x when perception turns on.
"""

from __future__ import annotations

import copy

import torch
from rsl_rl.models import MLPModel
from rsl_rl.modules import RNN, HiddenState
from tensordict import TensorDict
from torch import nn

from lca.learn.encoders import HeightmapEncoder


class PerceptiveMLPModel(MLPModel):
    """MLPModel whose input also includes one image group passed through a HeightmapEncoder."""

    is_recurrent = False

    def __init__(
        self,
        obs: TensorDict,
        obs_groups: dict[str, list[str]],
        obs_set: str,
        output_dim: int,
        hidden_dims: tuple[int, ...] | list[int] = (512, 256, 128),
        activation: str = "elu",
        obs_normalization: bool = False,
        distribution_cfg: dict | None = None,
        encoder_cfg: dict | None = None,
    ) -> None:
        encoder_cfg = dict(encoder_cfg or {})
        self._z_dim = int(encoder_cfg.get("latent_dim", 32))
        super().__init__(
            obs,
            obs_groups,
            obs_set,
            output_dim,
            hidden_dims,
            activation,
            obs_normalization,
            distribution_cfg,
        )
        self.encoder = HeightmapEncoder(
            shape=self.image_shape, activation=activation, **encoder_cfg
        )

    def _get_obs_dim(
        self, obs: TensorDict, obs_groups: dict, obs_set: str
    ) -> tuple[list[str], int]:
        flat, images = [], []
        for group in obs_groups[obs_set]:
            (images if obs[group].dim() == 4 else flat).append(group)
        if len(images) != 1:
            raise ValueError(f"{obs_set}: expected exactly one image group, got {images}")
        self.image_group = images[0]
        self.image_shape = [int(d) for d in obs[self.image_group].shape[1:]]
        return flat, sum(obs[g].shape[-1] for g in flat)

    def _get_latent_dim(self) -> int:
        return self.obs_dim + self._z_dim

    def get_kl_divergence(self, old_params, new_params) -> torch.Tensor:
        """PPO's adaptive schedule calls this once per mini-batch; the trainer logs the mean."""
        kl = super().get_kl_divergence(old_params, new_params)
        if hasattr(self, "kl_values"):
            self.kl_values.append(float(kl.mean()))
        return kl

    def _features(self, obs: TensorDict) -> torch.Tensor:
        flat = MLPModel.get_latent(self, obs)
        return torch.cat([flat, self.encoder(obs[self.image_group])], dim=-1)

    def get_latent(
        self, obs: TensorDict, masks: torch.Tensor | None = None, hidden_state: HiddenState = None
    ) -> torch.Tensor:
        return self._features(obs)

    def as_jit(self) -> nn.Module:
        return _ExportPerceptiveMLP(self)

    def as_onnx(self, verbose: bool = False) -> nn.Module:
        return _ExportPerceptiveMLP(self)


class PerceptiveRNNModel(PerceptiveMLPModel):
    """[proprioception, z] -> LSTM/GRU -> MLP head."""

    is_recurrent = True

    def __init__(
        self,
        obs: TensorDict,
        obs_groups: dict[str, list[str]],
        obs_set: str,
        output_dim: int,
        hidden_dims: tuple[int, ...] | list[int] = (512, 256, 128),
        activation: str = "elu",
        obs_normalization: bool = False,
        distribution_cfg: dict | None = None,
        encoder_cfg: dict | None = None,
        rnn_type: str = "lstm",
        rnn_hidden_dim: int = 256,
        rnn_num_layers: int = 1,
    ) -> None:
        self._rnn_dim = rnn_hidden_dim
        super().__init__(
            obs,
            obs_groups,
            obs_set,
            output_dim,
            hidden_dims,
            activation,
            obs_normalization,
            distribution_cfg,
            encoder_cfg,
        )
        self.rnn = RNN(self.obs_dim + self._z_dim, rnn_hidden_dim, rnn_num_layers, rnn_type)

    def _get_latent_dim(self) -> int:
        return self._rnn_dim

    def get_latent(
        self, obs: TensorDict, masks: torch.Tensor | None = None, hidden_state: HiddenState = None
    ) -> torch.Tensor:
        return self.rnn(self._features(obs), masks, hidden_state).squeeze(0)

    def reset(self, dones: torch.Tensor | None = None, hidden_state: HiddenState = None) -> None:
        self.rnn.reset(dones, hidden_state)

    def get_hidden_state(self) -> HiddenState:
        return self.rnn.hidden_state

    def detach_hidden_state(self, dones: torch.Tensor | None = None) -> None:
        self.rnn.detach_hidden_state(dones)

    def as_jit(self) -> nn.Module:
        return _ExportPerceptiveRNN(self)

    def as_onnx(self, verbose: bool = False) -> nn.Module:
        return _OnnxPerceptiveRNN(self)


class _ExportPerceptiveMLP(nn.Module):
    """Deterministic policy: (obs, heightmap) -> actions, for TorchScript and ONNX."""

    is_recurrent = False

    def __init__(self, model: PerceptiveMLPModel):
        super().__init__()
        self.obs_normalizer = copy.deepcopy(model.obs_normalizer)
        self.encoder = copy.deepcopy(model.encoder)
        self.mlp = copy.deepcopy(model.mlp)
        self.head = model.distribution.as_deterministic_output_module()
        self.obs_dim = model.obs_dim
        self.image_shape = model.image_shape
        self.input_names = ["obs", model.image_group]
        self.output_names = ["actions"]

    def forward(self, obs: torch.Tensor, heightmap: torch.Tensor) -> torch.Tensor:
        x = torch.cat([self.obs_normalizer(obs), self.encoder(heightmap)], dim=-1)
        return self.head(self.mlp(x))

    @torch.jit.export
    def reset(self) -> None:
        pass

    def get_dummy_inputs(self) -> tuple[torch.Tensor, ...]:
        return torch.zeros(1, self.obs_dim), torch.zeros(1, *self.image_shape)


class _ExportPerceptiveRNN(nn.Module):
    """LSTM policy for TorchScript: the hidden state lives inside; call `reset()` at episode
    starts. (obs, heightmap) -> actions."""

    is_recurrent = True

    def __init__(self, model: PerceptiveRNNModel):
        super().__init__()
        if not isinstance(model.rnn.rnn, nn.LSTM):
            raise NotImplementedError("export supports LSTM actors")
        self.obs_normalizer = copy.deepcopy(model.obs_normalizer)
        self.encoder = copy.deepcopy(model.encoder)
        self.rnn = copy.deepcopy(model.rnn.rnn)
        self.mlp = copy.deepcopy(model.mlp)
        self.head = model.distribution.as_deterministic_output_module()
        self.obs_dim = model.obs_dim
        self.image_shape = model.image_shape
        layers, hidden = self.rnn.num_layers, self.rnn.hidden_size
        self.register_buffer("hidden_state", torch.zeros(layers, 1, hidden))
        self.register_buffer("cell_state", torch.zeros(layers, 1, hidden))
        self.input_names = ["obs", model.image_group, "h_in", "c_in"]
        self.output_names = ["actions", "h_out", "c_out"]

    def step(
        self, obs: torch.Tensor, heightmap: torch.Tensor, h: torch.Tensor, c: torch.Tensor
    ) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        x = torch.cat([self.obs_normalizer(obs), self.encoder(heightmap)], dim=-1).unsqueeze(0)
        x, (h, c) = self.rnn(x, (h, c))
        return self.head(self.mlp(x.squeeze(0))), h, c

    def forward(self, obs: torch.Tensor, heightmap: torch.Tensor) -> torch.Tensor:
        actions, h, c = self.step(obs, heightmap, self.hidden_state, self.cell_state)
        self.hidden_state[:] = h
        self.cell_state[:] = c
        return actions

    @torch.jit.export
    def reset(self) -> None:
        self.hidden_state[:] = 0.0
        self.cell_state[:] = 0.0


class _OnnxPerceptiveRNN(_ExportPerceptiveRNN):
    """ONNX takes and returns the state: (obs, heightmap, h_in, c_in) -> (actions, h_out, c_out)."""

    def forward(self, obs, heightmap, h_in, c_in):  # noqa: D102
        return self.step(obs, heightmap, h_in, c_in)

    def get_dummy_inputs(self) -> tuple[torch.Tensor, ...]:
        return (
            torch.zeros(1, self.obs_dim),
            torch.zeros(1, *self.image_shape),
            torch.zeros_like(self.hidden_state),
            torch.zeros_like(self.cell_state),
        )
