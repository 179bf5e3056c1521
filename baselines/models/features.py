"""A features extractor that standardises the flat observation with fixed statistics.

The observation mixes metres, seconds, flags and (per the design) float32 residuals of order
1e-8; an MLP clones the expert far better on standardised inputs. The mean and scale are
buffers, so they travel inside the SB3 ``.zip`` and ``predict`` on raw observations just
works (no VecNormalize file to carry). They are set once from demonstrations
(:func:`set_statistics`); the scale has a floor so that near-constant entries (flags,
residuals) are not blown up into noise.
"""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import torch as th
from stable_baselines3.common.torch_layers import BaseFeaturesExtractor

__all__ = ["ACTIVATIONS", "SCALE_FLOOR", "StandardizeObservation", "set_statistics"]

ACTIVATIONS = ("ReLU", "Tanh", "ELU", "LeakyReLU", "SiLU", "GELU", "Sigmoid")
"""The ``torch.nn`` activations a hyperparameter file may name and a model file may carry."""

SCALE_FLOOR = 0.05


class StandardizeObservation(BaseFeaturesExtractor):
    """``(obs - mean) / scale`` with buffers (identity until :func:`set_statistics`)."""

    mean: th.Tensor
    scale: th.Tensor

    def __init__(self, observation_space: gym.spaces.Box) -> None:
        if not isinstance(observation_space, gym.spaces.Box) or len(observation_space.shape) != 1:
            raise ValueError(f"StandardizeObservation needs a flat Box, got {observation_space}")
        n = int(observation_space.shape[0])
        super().__init__(observation_space, n)
        self.register_buffer("mean", th.zeros(n))
        self.register_buffer("scale", th.ones(n))

    def forward(self, observations: th.Tensor) -> th.Tensor:
        return (observations.float() - self.mean) / self.scale


def set_statistics(policy: th.nn.Module, observations: np.ndarray) -> bool:
    """Set every :class:`StandardizeObservation` of ``policy`` from ``observations``."""
    obs = np.asarray(observations, np.float64)
    mean = th.as_tensor(obs.mean(axis=0), dtype=th.float32)
    scale = th.as_tensor(np.maximum(obs.std(axis=0), SCALE_FLOOR), dtype=th.float32)
    found = False
    for module in policy.modules():
        if isinstance(module, StandardizeObservation):
            module.mean.copy_(mean.to(module.mean.device))
            module.scale.copy_(scale.to(module.scale.device))
            found = True
    return found
