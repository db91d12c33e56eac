"""Heightmap encoders: H (C x H x W) -> z (latent_dim). Leading batch dims are folded, so the
same module serves (B, ...) rollouts and (T, B, ...) recurrent updates."""

from __future__ import annotations

import torch
from rsl_rl.utils import resolve_nn_activation
from torch import nn


def _mlp(in_dim: int, hidden: list[int], out_dim: int, activation: str) -> list[nn.Module]:
    layers: list[nn.Module] = []
    for width in hidden:
        layers += [nn.Linear(in_dim, width), resolve_nn_activation(activation)]
        in_dim = width
    layers.append(nn.Linear(in_dim, out_dim))
    return layers


class HeightmapEncoder(nn.Module):
    """`kind="cnn"`: 3x3 stride-1 convolutions (each optionally followed by max-pooling),
    then an MLP head; `kind="mlp"`: an MLP over the flattened map. Both use `hidden_dims` for
    the head (paper: {256, 256})."""

    def __init__(
        self,
        kind: str,
        shape: tuple[int, int, int],
        hidden_dims: list[int],
        latent_dim: int,
        conv_channels: list[int],
        kernel_size: int = 3,
        stride: int = 1,
        pool: int = 0,
        activation: str = "elu",
    ):
        super().__init__()
        self.kind = kind
        self.shape = [int(d) for d in shape]
        self.latent_dim = latent_dim
        channels, height, width = self.shape
        layers: list[nn.Module] = []
        if kind == "cnn":
            for out in conv_channels:
                layers += [
                    nn.Conv2d(channels, out, kernel_size, stride, padding=kernel_size // 2),
                    resolve_nn_activation(activation),
                ]
                channels = out
                height = (height + 2 * (kernel_size // 2) - kernel_size) // stride + 1
                width = (width + 2 * (kernel_size // 2) - kernel_size) // stride + 1
                if pool > 1:
                    layers.append(nn.MaxPool2d(pool))
                    height, width = height // pool, width // pool
        elif kind != "mlp":
            raise ValueError(f"encoder.kind: unknown '{kind}'; allowed: cnn, mlp")
        layers.append(nn.Flatten())
        layers += _mlp(channels * height * width, list(hidden_dims), latent_dim, activation)
        self.net = nn.Sequential(*layers)

    def forward(self, image: torch.Tensor) -> torch.Tensor:
        lead = list(image.shape[:-3])
        z = self.net(image.reshape([-1] + self.shape))
        return z.reshape(lead + [self.latent_dim])
