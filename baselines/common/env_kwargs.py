"""Keyword arguments for ``gym.make`` from a command line or a recipe, tried before any work.

``--env-kwargs`` JSON and a recipe's ``env_kwargs`` reach the env's constructor; an unknown
name or a wrongly typed value would otherwise surface mid-run as a ``TypeError`` traceback
(or as every run of a benchmark failing). Building the env once with them turns that into one
``ValueError`` naming the field. Only registered ids are built (``check_env_id``), so no
spelling of an id or a kwarg imports a module of its own.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping
from typing import Any

import gymnasium as gym

from sgc_env import check_env_id
from sgc_env.scenario.bounded import escaped
from sgc_env.scenario.caps import CAPS, cap

__all__ = ["check_env_kwargs", "check_kwarg_values"]

_FREQUENCY = "sim_frequency"


def check_kwarg_values(kwargs: Mapping[str, Any], field: str) -> None:
    """The kwargs that multiply the work of every step within their caps, before any env is
    built with them: ``sim_frequency`` (PyBullet steps per second) up to
    ``CAPS["sim_frequency"]``."""
    if _FREQUENCY not in kwargs:
        return
    value, limit = kwargs[_FREQUENCY], cap(_FREQUENCY)
    if isinstance(value, bool) or not isinstance(value, int) or not 1 <= value <= limit:
        raise ValueError(f"{field}: {_FREQUENCY} must be an integer in [1, {limit}] Hz "
                         f"({CAPS[_FREQUENCY].reason}), got {escaped(repr(value))}")  # fmt: skip


def check_env_kwargs(env_id: str, kwargs: Mapping[str, Any] | None, field: str) -> dict[str, Any]:
    """``kwargs`` as a dict once ``gym.make(env_id, **kwargs)`` has accepted them."""
    check_env_id(env_id, field)
    if kwargs is None:
        return {}
    if not isinstance(kwargs, Mapping) or not all(isinstance(k, str) for k in kwargs):
        raise ValueError(f"{field}: expected a mapping of names to values, got "
                         f"{escaped(repr(kwargs))}")  # fmt: skip
    if not kwargs:
        return {}
    check_kwarg_values(kwargs, field)
    try:
        with warnings.catch_warnings():  # a trial: the real make warns again, if it gets there
            warnings.simplefilter("ignore")
            env = gym.make(env_id, **kwargs)
    except (TypeError, ValueError, KeyError, AttributeError, OSError) as exc:
        first = str(exc).split(" was raised from the environment creator")[0].splitlines()[0]
        raise ValueError(f"{field}: {env_id} does not take {escaped(dict(kwargs))}: "
                         f"{escaped(first)}") from None  # fmt: skip
    env.close()
    return dict(kwargs)
