"""Shared fixtures: every env a test makes is closed when the test ends.

An unclosed env keeps its PyBullet client (and its memory) until the process exits, so a
suite that forgets ``close()`` grows with every test. :func:`closing_every_env` records each
:class:`~sgc_env.envs.SGCEnv` constructed while it is active (``gym.make`` ones included) and
closes those still open on exit; the autouse fixture wraps every test in it.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator

import pytest

from sgc_env.envs import SGCEnv


@contextlib.contextmanager
def closing_every_env() -> Iterator[list[SGCEnv]]:
    """Track the SGCEnv instances constructed inside the block; close the open ones after."""
    made: list[SGCEnv] = []
    original = SGCEnv.__init__

    def tracking_init(self: SGCEnv, *args: object, **kwargs: object) -> None:
        made.append(self)  # before building: a constructor that fails is cleaned up too
        original(self, *args, **kwargs)

    SGCEnv.__init__ = tracking_init  # type: ignore[method-assign]
    try:
        yield made
    finally:
        SGCEnv.__init__ = original  # type: ignore[method-assign]
        for env in made:
            if getattr(env, "sim", None) is not None:
                env.close()


@pytest.fixture(autouse=True)
def close_envs() -> Iterator[list[SGCEnv]]:
    with closing_every_env() as made:
        yield made
