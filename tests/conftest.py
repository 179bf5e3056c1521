"""Shared fixtures: every env a test makes is closed when the test ends.

An unclosed env keeps its PyBullet client (and its memory) until it is collected, so a suite
that forgets ``close()`` grows with every test. :func:`closing_every_env` records each
:class:`~sgc_env.envs.SGCEnv` constructed while it is active (``gym.make`` ones included),
weakly, so that envs a test drops are still collected (and freed) as usual, and closes those
still alive and open on exit; the autouse fixture wraps every test in it.
"""

from __future__ import annotations

import contextlib
import weakref
from collections.abc import Iterator

import gymnasium as gym
import pytest

from sgc_env.envs import SGCEnv


@contextlib.contextmanager
def closing_every_env() -> Iterator[weakref.WeakSet[SGCEnv]]:
    """Track the SGCEnv instances constructed inside the block; close the open ones after."""
    made: weakref.WeakSet[SGCEnv] = weakref.WeakSet()
    original = SGCEnv.__init__

    def tracking_init(self: SGCEnv, *args: object, **kwargs: object) -> None:
        made.add(self)  # before building: a constructor that fails is cleaned up too
        original(self, *args, **kwargs)

    SGCEnv.__init__ = tracking_init  # type: ignore[method-assign]
    try:
        yield made
    finally:
        SGCEnv.__init__ = original  # type: ignore[method-assign]
        for env in list(made):
            env.close()  # idempotent, and safe on an env whose constructor failed


@pytest.fixture(autouse=True)
def close_envs() -> Iterator[weakref.WeakSet[SGCEnv]]:
    with closing_every_env() as made:
        yield made


@pytest.fixture(params=["single", "batched"])
def make_env(request: pytest.FixtureRequest):  # type: ignore[no-untyped-def]
    """``gym.make`` or a batched env of one seen as a single env: a test that makes its env
    with this runs on both (tests/one_or_many.py)."""
    if request.param == "single":
        return gym.make
    from tests.one_or_many import BatchOfOne

    return BatchOfOne
