"""The planner's view of an env's current state, for the policies that read it on any id.

The expert and the comparison controllers decode the planner's observation
(:mod:`sgc_env.observation`); every id observes the learner's view. Every SGC env hands
out the planner's view of its current state (``SGCEnv.planner_observation``), so a planner
policy acts on the very state the learner sees: :func:`planner_observation` reads it from a
plain, wrapped or vector env (one row per sub-env). :func:`planner_reader` is the one home of
the rule the policies follow: built on an env of another view, a policy's ``predict`` acts on
the env's planner view, after checking that the observation it was handed is the one the env
last returned (:class:`PlannerReader`). :class:`OnPlannerView` puts a policy that reads
observations only (``SGCExpert(model=...)``, one of your own) on such an env. That is how
demonstrations store the learner's observation with the expert's action, and how DAgger labels
the learner's states.
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np

from baselines.common.sub_envs import is_vector, sub_env, vector_base

__all__ = [
    "OnPlannerView",
    "PlannerReader",
    "last_observation",
    "observed_view",
    "planner_input",
    "planner_observation",
    "planner_reader",
]


def observed_view(env: Any) -> str:
    """The name of the view ``env`` (or a vector env's first sub-env, in process or behind
    processes) observes; ``"planner"`` for an env that does not say (not an SGC env: the
    policy's own checks name it)."""
    return getattr(sub_env(env, 0).unwrapped, "observation_view", "planner")


def _base(env: Any) -> Any:
    base = getattr(env, "unwrapped", env)
    if getattr(base, "planner_observation", None) is None:
        raise TypeError(f"{type(base).__name__} is not an SGC environment (no planner view)")
    return base


def _in_process(env: Any) -> list[Any] | None:
    """The base envs of a vector env whose sub-envs are in this process (one read of
    ``envs``: the batched env brings its sub-envs up to date on it), else None."""
    envs = getattr(vector_base(env), "envs", None)
    return None if envs is None else [_base(sub) for sub in envs]


def planner_observation(env: Any) -> np.ndarray:
    """The planner's view of ``env``'s current state: (size,) float32 for a plain or wrapped
    env, (N, size) for a vector env (Gymnasium's or SB3's, in process or behind processes)."""
    if not is_vector(env):
        return _base(env).planner_observation()
    bases = _in_process(env)
    if bases is not None:
        rows = [base.planner_observation() for base in bases]
    elif hasattr(env, "env_method"):  # SB3's SubprocVecEnv
        rows = env.env_method("planner_observation")
    else:  # Gymnasium's AsyncVectorEnv
        rows = vector_base(env).call("planner_observation")
    return np.stack(rows)


def last_observation(env: Any) -> np.ndarray:
    """The flat observation ``env`` last handed out (by ``reset``, ``step``, ``apply_impulse``
    or ``restore_state``; a goal env's ``observation`` entry), in its own view: (size,), or
    (N, size) for a vector env (``SGCEnv.last_observation``, which the batched env keeps up
    to date in its sub-envs)."""
    if not is_vector(env):
        return _base(env).last_observation
    bases = _in_process(env)
    if bases is not None:
        return np.stack([base.last_observation for base in bases])
    return np.stack(vector_base(env).get_attr("last_observation"))  # behind processes


def _flat(observation: Any) -> np.ndarray:
    """The flat observation of a plain or goal-conditioned (Dict) one, as an array."""
    return np.asarray(observation["observation"] if isinstance(observation, dict) else observation)


def _observation_shape(env: Any) -> tuple[int, ...]:
    """The shape of ``env``'s flat observations (a goal env's ``observation`` entry): (size,),
    or (N, size) for a vector env (Gymnasium's batched spaces have single ones; SB3's are
    single)."""
    space = env.observation_space
    if is_vector(env):
        space = getattr(env, "single_observation_space", None) or space
    if isinstance(space, gym.spaces.Dict):
        space = space["observation"]
    shape = tuple(space.shape)
    return (env.num_envs, *shape) if is_vector(env) else shape


class PlannerReader:
    """The planner's view of the current state of ``env``, an env that observes another view,
    for a planner policy built on it (``reader`` names the policy in errors).

    The contract: :meth:`read` is handed the observation ``env`` just returned (from
    ``reset``, ``step``, ``apply_impulse`` or ``restore_state``; for a vector env the batch it
    returned), as in any rollout, and gives the planner's view of that same state. The values
    of a learner's observation cannot be turned back into a planner's (it lacks the precision
    residuals and the absolute states the expert reads), so the state is read from ``env``;
    the observation is checked to be ``env``'s last one, so a policy asked about another
    state (an offline observation, another env's, one from before a later step) raises a
    ValueError instead of acting on the wrong state.
    """

    def __init__(self, env: Any, reader: str) -> None:
        self.env = env
        self.reader = reader
        self.view = observed_view(env)
        self._shape = _observation_shape(env)

    def read(self, observation: Any) -> np.ndarray:
        """The planner's view of ``env``'s current state, (size,) or (N, size) as
        ``observation`` (a plain or goal-conditioned one, or a batch of one of a single env),
        which must be ``env``'s last."""
        flat = _flat(observation)
        if flat.shape == (1, *self._shape) and not is_vector(self.env):  # a batch of one
            return self.read(flat[0])[None]
        if flat.shape != self._shape:
            hint = ""
            if flat.shape[-1:] == planner_observation(self.env).shape[-1:]:
                hint = " (the planner's view's size: hand it the env's own observation)"
            raise ValueError(
                f"{self.reader}: observation has shape {flat.shape}{hint}; it acts on the "
                f"current state of the env it was built on, which observes the {self.view!r} "
                f"view with observations of shape {self._shape}"
            )
        if not np.array_equal(flat, last_observation(self.env), equal_nan=True):
            raise ValueError(
                f"{self.reader}: this observation is not the one its env last returned. Built "
                f"on an env of the {self.view!r} view it acts on the env's current state "
                "(env.unwrapped.planner_observation()), so it must be asked about the "
                "observation that env just returned; to act on observations alone, build it "
                "on an env made with gym.make(id, observation='planner')"
            )
        return planner_observation(self.env)


def planner_input(planner: PlannerReader | None, observation: Any) -> np.ndarray:
    """What a planner policy acts on: the planner's view read by ``planner`` (an env of
    another view), else the flat observation it was handed (a goal env's Dict read through its
    ``observation`` entry)."""
    return _flat(observation) if planner is None else planner.read(observation)


def planner_reader(env: Any, reader: str) -> PlannerReader | None:
    """A :class:`PlannerReader` for a planner policy built on ``env``, or None when ``env``
    observes the planner's view (the policy then reads the observation it is handed as it is,
    offline observations included)."""
    return None if observed_view(env) == "planner" else PlannerReader(env, reader)


class OnPlannerView:
    """A policy that reads planner observations only (``policy``) on ``env``, an env that
    observes another view: ``predict`` acts on the planner's view of ``env``'s current state,
    under the contract of :class:`PlannerReader`.

    The expert and the comparison controllers built on ``env`` need no wrapping: they read it
    themselves (:func:`planner_reader`).
    """

    def __init__(self, policy: Any, env: Any) -> None:
        self.policy = policy
        self.env = env
        self._reader = PlannerReader(env, type(policy).__name__)

    def predict(
        self,
        observation: Any,
        state: Any = None,
        episode_start: Any = None,
        deterministic: bool = True,
    ) -> tuple[np.ndarray, Any]:
        planner = self._reader.read(observation)
        return self.policy.predict(planner, state, episode_start, deterministic)
