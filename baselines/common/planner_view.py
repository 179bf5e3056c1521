"""The planner's view of an env's current state, for the policies that read it on any id.

The expert and the comparison controllers decode the planner's observation
(:mod:`sgc_env.observation`); the newest ids observe the learner's view. Every SGC env hands
out the planner's view of its current state (``SGCEnv.planner_observation``), so a planner
policy acts on the very state the learner sees: :func:`planner_observation` reads it from a
plain, wrapped or vector env (one row per sub-env), and :class:`OnPlannerView` puts a planner
policy on an env of another view. That is how demonstrations store the learner's observation
with the expert's action, and how DAgger labels the learner's states.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from baselines.common.sub_envs import is_vector, sub_env

__all__ = ["OnPlannerView", "observed_view", "planner_observation"]


def observed_view(env: Any) -> str:
    """The name of the view ``env`` (or a vector env's first sub-env, in process or behind
    processes) observes; ``"planner"`` for an env that does not say (not an SGC env: the
    policy's own checks name it)."""
    return getattr(sub_env(env, 0).unwrapped, "observation_view", "planner")


def _base_planner_observation(env: Any) -> np.ndarray:
    base = getattr(env, "unwrapped", env)
    method = getattr(base, "planner_observation", None)
    if method is None:
        raise TypeError(f"{type(base).__name__} is not an SGC environment (no planner view)")
    return method()


def planner_observation(env: Any) -> np.ndarray:
    """The planner's view of ``env``'s current state: (size,) float32 for a plain or wrapped
    env, (N, size) for a vector env (Gymnasium's or SB3's, in process or behind processes)."""
    if not is_vector(env):
        return _base_planner_observation(env)
    envs = getattr(env, "envs", None)
    if envs is not None:
        rows = [_base_planner_observation(sub) for sub in envs]
    elif hasattr(env, "env_method"):  # SB3's SubprocVecEnv
        rows = env.env_method("planner_observation")
    else:  # Gymnasium's AsyncVectorEnv
        rows = env.call("planner_observation")
    return np.stack(rows)


class OnPlannerView:
    """A planner policy (``policy``) on ``env``, an env that observes another view.

    ``predict`` acts on the planner's view of ``env``'s current state: the observation it is
    handed must be ``env``'s latest (as in any rollout); its shape is checked, and its values
    are not read. Offline observations of the learner's view cannot be labelled: they lack what
    the expert reads (precision residuals, absolute states).
    """

    def __init__(self, policy: Any, env: Any) -> None:
        self.policy = policy
        self.env = env
        if is_vector(env):  # Gymnasium's batched spaces have single ones; SB3's are single
            single = getattr(env, "single_observation_space", None) or env.observation_space
            self._shape: tuple[int, ...] = (env.num_envs, *single.shape)
        else:
            self._shape = env.observation_space.shape

    def predict(
        self,
        observation: Any,
        state: Any = None,
        episode_start: Any = None,
        deterministic: bool = True,
    ) -> tuple[np.ndarray, Any]:
        shape = np.shape(observation)
        if shape != self._shape:
            raise ValueError(
                f"observation has shape {shape}; this policy acts on the current state of an env "
                f"whose observations have shape {self._shape}"
            )
        planner = planner_observation(self.env)
        return self.policy.predict(planner, state, episode_start, deterministic)
