"""Training-only action-rate term: a learner that is paid to move smoothly.

The harness scores smoothness (the largest one-tick change of acceleration, the "kink"), but
the env's reward pays for tracking only, so nothing asks a learner to be smooth: a policy that
reacts to a goal switch with a jump of its action scores the same as one that blends into the
next course. :class:`ActionRatePenalty` charges, on every step after an episode's first,

    weight * mean_k (a_t[k] - a_{t-1}[k])^2

(the mean over the action's components, in the env's action units), the temporal term of
CAPS (Mysore et al., 2021) moved into the reward, where every algorithm sees it without a
change to its loss. A one-tick change of action is a one-tick change of acceleration (the
force and torque act for the tick), so the term charges exactly what the kink measures.
The exploration noise adds a constant ``2 sigma^2`` to its expectation, which no policy can
change, so it does not bias the ranking of policies. Like the other shaping it is applied
to the training envs only (evaluation scores goals and kinks, not rewards) and sits below
``VecNormalize``.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from gymnasium import spaces
from stable_baselines3.common.vec_env import VecEnv, VecEnvWrapper

from baselines.common.value_types import check_weight

__all__ = ["ActionRatePenalty"]


class ActionRatePenalty(VecEnvWrapper):
    """Subtract ``weight`` times the mean squared one-tick change of action (module
    docstring); the first step of every episode is not charged."""

    def __init__(self, venv: VecEnv, weight: float) -> None:
        self.weight = check_weight(weight, "action_rate")
        space = venv.action_space
        if not isinstance(space, spaces.Box):
            raise ValueError(f"action_rate: needs a Box action space, got {space}")
        super().__init__(venv)
        self._low, self._high = space.low, space.high
        shape = (venv.num_envs, int(np.prod(venv.action_space.shape or (1,))))
        self._previous = np.zeros(shape, dtype=np.float64)
        self._started = np.zeros(venv.num_envs, dtype=bool)
        self._actions = np.zeros(shape, dtype=np.float64)

    def reset(self) -> Any:
        self._started[:] = False
        return self.venv.reset()

    def step_async(self, actions: np.ndarray) -> None:
        clipped = np.clip(np.asarray(actions, dtype=np.float64), self._low, self._high)
        self._actions = clipped.reshape(self._previous.shape)
        self.venv.step_async(actions)

    def step_wait(self) -> Any:
        obs, rewards, dones, infos = self.venv.step_wait()
        change = np.mean((self._actions - self._previous) ** 2, axis=1)
        charged = rewards - self.weight * np.where(self._started, change, 0.0)
        self._previous = self._actions
        self._started = ~np.asarray(dones, dtype=bool)
        return obs, charged.astype(np.asarray(rewards).dtype), dones, infos
