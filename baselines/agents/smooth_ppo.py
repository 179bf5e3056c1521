"""PPO that is asked to move smoothly: CAPS's temporal and spatial terms in PPO's own loss.

A learner paid for tracking only settles on stiff feedback: on the paper's three-rod scene the
plain per-body PPO meets every goal while its action changes by ~8 m/s^2 a tick at the
median and by over 100 m/s^2 at its worst, 10x the expert's largest kink. CAPS (Mysore et al.,
"Regularizing action policies for smooth control with reinforcement learning", ICRA 2021)
adds to the actor's loss, for the policy's mean action ``mu``:

- temporal: ``temporal * |mu(s_t) - mu(s_t+1)|`` over consecutive states of one episode, the
  one-tick change of action (and of acceleration) that the harness's kink measures;
- spatial: ``spatial * |mu(s) - mu(s + e)|``, ``e ~ N(0, spatial_std^2)`` in observation
  units, so that nearby states get nearby actions.

(Euclidean norms in action units, averaged over the minibatch.) SB3's PPO computes its loss in
one method; rather than a copy of it, :class:`SmoothPPO` hands each minibatch's successor
states to the loss through its rollout buffer (:class:`SuccessorRolloutBuffer`) and adds the
terms' gradient where PPO back-propagates its surrogate (:class:`_AddGradient`), so they share
PPO's minibatch, gradient clipping and optimizer step. With both weights 0 this is PPO, step
for step.
"""

from __future__ import annotations

from collections.abc import Generator
from typing import Any

import numpy as np
import torch as th
from stable_baselines3 import PPO
from stable_baselines3.common.buffers import RolloutBuffer
from stable_baselines3.common.type_aliases import RolloutBufferSamples

from baselines.common.value_types import check_weight

__all__ = ["SmoothPPO", "SuccessorRolloutBuffer"]


class SuccessorRolloutBuffer(RolloutBuffer):
    """A :class:`RolloutBuffer` that also keeps, for the minibatch it last handed out, each
    state's successor in the same episode and whether it has one (the rollout's last step and
    an episode's last state have none)."""

    successors: th.Tensor | None = None
    has_successor: th.Tensor | None = None

    def get(self, batch_size: int | None = None) -> Generator[RolloutBufferSamples, None, None]:
        if not self.generator_ready:  # before PPO's get() flattens env by env
            following = np.ones_like(self.episode_starts, dtype=bool)
            following[:-1] = self.episode_starts[1:] == 0
            following[-1] = False
            self._successor_index = np.arange(self.buffer_size * self.n_envs) + 1
            self._has_successor = self.swap_and_flatten(following[..., None])[:, 0]
            self._successor_index[~self._has_successor] = 0
        yield from super().get(batch_size)

    def _get_samples(self, batch_inds: np.ndarray, env: Any = None) -> RolloutBufferSamples:
        self.successors = self.to_torch(self.observations[self._successor_index[batch_inds]])
        self.has_successor = self.to_torch(self._has_successor[batch_inds])
        return super()._get_samples(batch_inds, env)


class _AddGradient(th.autograd.Function):
    """``carrier`` unchanged forward; backward also sends a gradient of 1 into ``extra`` (a
    scalar loss), so whatever back-propagates through ``carrier`` also minimises ``extra``."""

    @staticmethod
    def forward(ctx: Any, carrier: th.Tensor, extra: th.Tensor) -> th.Tensor:
        return carrier.clone()

    @staticmethod
    def backward(ctx: Any, grad: th.Tensor) -> tuple[th.Tensor, th.Tensor]:
        return grad, th.ones((), dtype=grad.dtype, device=grad.device)


class SmoothPPO(PPO):
    """:class:`~stable_baselines3.PPO` with CAPS's smoothness terms in its loss (module
    docstring): ``temporal`` and ``spatial`` weigh them, ``spatial_std`` is the state
    perturbation."""

    rollout_buffer: SuccessorRolloutBuffer

    def __init__(
        self,
        *args: Any,
        temporal: float = 0.0,
        spatial: float = 0.0,
        spatial_std: float = 0.05,
        **kwargs: Any,
    ) -> None:
        self.temporal = check_weight(temporal, "temporal")
        self.spatial = check_weight(spatial, "spatial")
        self.spatial_std = check_weight(spatial_std, "spatial_std")
        kwargs.setdefault("rollout_buffer_class", SuccessorRolloutBuffer)
        super().__init__(*args, **kwargs)

    def _excluded_save_params(self) -> list[str]:
        return [*super()._excluded_save_params(), "rollout_buffer_class"]

    def train(self) -> None:
        if not (self.temporal or self.spatial):
            return super().train()
        policy = self.policy
        evaluate_actions = policy.evaluate_actions

        def smoothed(obs: Any, actions: th.Tensor) -> tuple[Any, th.Tensor, Any]:
            values, log_prob, entropy = evaluate_actions(obs, actions)
            return values, _AddGradient.apply(log_prob, self.smoothness_loss(obs)), entropy

        self._terms: dict[str, list[float]] = {"temporal": [], "spatial": []}
        policy.evaluate_actions = smoothed  # type: ignore[method-assign]
        try:
            super().train()
        finally:
            del policy.evaluate_actions  # the class's method again
        for key, values in self._terms.items():
            if values:
                self.logger.record(f"smooth/{key}", float(np.mean(values)))
        return None

    def _mean_action(self, obs: th.Tensor) -> th.Tensor:
        distribution = self.policy.get_distribution(obs).distribution
        if not isinstance(distribution, th.distributions.Distribution):
            raise ValueError("SmoothPPO: needs one action distribution (a Box action space)")
        return distribution.mean

    def smoothness_loss(self, obs: th.Tensor) -> th.Tensor:
        """The weighted CAPS terms of one minibatch (its successors from the buffer)."""
        mean = self._mean_action(obs)
        loss = th.zeros((), device=mean.device)
        if self.temporal:
            buffer = self.rollout_buffer
            assert buffer.successors is not None and buffer.has_successor is not None
            step = (mean - self._mean_action(buffer.successors)).norm(dim=-1)
            temporal = (step * buffer.has_successor).sum() / buffer.has_successor.sum().clamp(min=1)
            loss = loss + self.temporal * temporal
            self._terms["temporal"].append(temporal.item())
        if self.spatial:
            noisy = obs + self.spatial_std * th.randn_like(obs)
            spatial = (mean - self._mean_action(noisy)).norm(dim=-1).mean()
            loss = loss + self.spatial * spatial
            self._terms["spatial"].append(spatial.item())
        return loss
