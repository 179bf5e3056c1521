"""The one accessor for sub-envs of vector envs: in-process, behind processes, or none at all.

SB3's ``DummyVecEnv`` and Gymnasium's ``SyncVectorEnv`` hold their sub-envs in ``.envs``;
``SubprocVecEnv`` and ``AsyncVectorEnv`` keep them in other processes, where only
``get_attr`` reaches them. Both kinds (and plain or wrapped envs) go through :func:`sub_env`;
Gymnasium's vector wrappers forward neither, so they are looked through (:func:`vector_base`).
"""

from __future__ import annotations

import sys
from types import SimpleNamespace
from typing import Any

import gymnasium as gym

__all__ = ["MODEL_ATTRIBUTES", "base_env", "is_vector", "sub_env", "vector_base"]

MODEL_ATTRIBUTES = (
    "scenario",
    "body_inertia",
    "torque_scale",
    "layout",
    "sim_frequency",
    "substeps",
    "use_torque",
    "observation_view",
)
"""What a model-based policy reads from the base env (fetched across processes by name)."""


def is_vector(env: Any) -> bool:
    """Whether ``env`` is a vector env (Gymnasium's or SB3's)."""
    if isinstance(env, gym.vector.VectorEnv):
        return True
    # An SB3 VecEnv exists only once SB3 is imported; not importing it here keeps torch out.
    vec_env = sys.modules.get("stable_baselines3.common.vec_env")
    return vec_env is not None and isinstance(env, vec_env.VecEnv)


def vector_base(env: Any) -> Any:
    """A Gymnasium vector env under its vector wrappers (``RecordEpisodeStatistics``, ...),
    whose ``envs``, ``call`` and ``get_attr`` they do not forward; any other env as it is
    (SB3's ``VecEnvWrapper`` forwards them itself)."""
    return env.unwrapped if isinstance(env, gym.vector.VectorEnv) else env


def _get_attr(env: Any, name: str, index: int) -> Any:
    try:  # SB3: get_attr(name, indices)
        return env.get_attr(name, [index])[0]
    except TypeError:  # Gymnasium: get_attr(name) for every sub-env
        return env.get_attr(name)[index]


def sub_env(env: Any, index: int = 0) -> Any:
    """Sub-env ``index`` of a vector env (SB3 or Gymnasium), or ``env`` itself.

    Sub-envs behind processes are represented by a stand-in whose ``unwrapped`` carries the
    :data:`MODEL_ATTRIBUTES`, read now (a random-scenario env redraws its scenario per reset).
    """
    if not is_vector(env):
        return env
    env = vector_base(env)
    envs = getattr(env, "envs", None)
    if envs is not None:
        return envs[index]
    values = {name: _get_attr(env, name, index) for name in MODEL_ATTRIBUTES}
    return SimpleNamespace(unwrapped=SimpleNamespace(**values))


def base_env(env: Any, index: int = 0) -> Any:
    """The base SGC env (or its stand-in) behind wrappers, or behind sub-env ``index``."""
    base = sub_env(env, index).unwrapped
    if not hasattr(base, "scenario"):
        raise TypeError(f"{type(base).__name__} is not an SGC environment (no scenario)")
    return base
