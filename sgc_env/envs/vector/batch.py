"""N sub-envs in shared PyBullet worlds, stepped together: the core of both vector env APIs.

Each sub-env is an ordinary :class:`~sgc_env.envs.sgc_env.SGCEnv` (or goal env) built on a
:class:`~.world.WorldView` of a :class:`~.world.SharedWorld`; the scenes are spread over
worlds of about :data:`SHARD_OBJECTS` bodies (why: there). A control
step gathers every stepping sub-env's drives, runs each world's substeps once, then observes
every sub-env. The Gymnasium (:mod:`.vector_env`) and SB3 (``baselines.agents.sb3_vec_env``)
adapters differ only in their reset conventions and in how they batch what this returns.

A sub-env that does not step in a call (it is being reset) still has bodies in the world that
the substeps integrate; its reset comes after the physics and overwrites their state, so it
starts exactly where a single env's reset would.

Plain ``SGCEnv`` sub-envs (every id but the goal-conditioned one; :data:`FAST_MIN_ENVS` or
more of them) step by the fast path,
:meth:`Batch.step_fast`: the single env's task rules run on all sub-envs at once
(:class:`~.task.BatchTask`), the sub-env objects brought up to date only
when :attr:`Batch.envs` hands them out. The goal env steps each sub-env's own
``_finish_step`` (:meth:`Batch.step`).
"""

from __future__ import annotations

import gc
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

import numpy as np

from sgc_env.episode_steps import check_episode_length

from ..actuation import clip_action
from ..sgc_env import SGCEnv
from ..task import GoalEvent
from .task import BatchTask
from .world import PropWorld, SharedWorld

__all__ = ["FAST_MIN_ENVS", "MAX_ENVS", "MAX_WORLDS", "SHARD_OBJECTS", "Batch", "check_num_envs",
           "scenes_per_world"]  # fmt: skip

MAX_ENVS = 1024
"""Most sub-envs per batch. Why a cap: with at most :data:`MAX_WORLDS` worlds, more scenes
crowd each world and its quadratic step cost (see :data:`SHARD_OBJECTS`) grows again; batches
beyond it were never measured."""

StepResult = tuple[Any, float, bool, bool, Any]


SHARD_OBJECTS = 8
"""Bodies per PyBullet world, about (props live in a client of their own, never stepped:
:attr:`~sgc_env.envs.vector.world.SharedWorld.props`). Why shards: PyBullet's
``stepSimulation`` costs O(objects^2) in one world even without collision shapes
(scripts/bench_world_step.py: about 2 us per body-step in worlds of 4 to 8 bodies, 11 at 64,
95 at 256), so the batch spreads its scenes over several worlds (clients); a world of one
body pays the per-call overhead of a step (4 us)."""

MAX_WORLDS = 24
"""Most worlds per batch: each PyBullet client holds ~28 MB, so more scenes share a world
once N scenes would need more (a 256-scene three-rod batch: 11 scenes of 7 objects per world,
~1.25 GB resident with SB3 imported; 32 worlds took it to 1.48 GB)."""


FAST_MIN_ENVS = 12
"""Fewest sub-envs that step by the numpy path (:class:`BatchTask`): its few hundred numpy calls
per step cost about the same for 1 sub-env as for 64 (~1.5 ms under load), more than a few
sub-envs' own Python; measured against the per-sub-env path, numpy/per-sub-env env-steps/s
were 0.31, 0.47, 0.90, 1.40 for 2, 4, 8, 16 rods and 0.45, 0.61, 1.07, 1.43 for three-rod
scenes."""


@contextmanager
def collector_paused() -> Iterator[None]:
    """Python's cyclic garbage collector held off for the block (left as it was if off).

    Why: a batched step allocates thousands of short-lived lists and tuples (PyBullet's
    arguments and readings) that die with the step and hold no cycles, but their count
    triggers collections of everything the sub-envs keep (for random three-rod scenes a
    noticeable share of the step; none for the rod). The count falls back as the step's
    objects are freed, so collection resumes after the block as before."""
    if not gc.isenabled():
        yield
        return
    gc.disable()
    try:
        yield
    finally:
        gc.enable()


def scenes_per_world(num_envs: int, objects: int) -> int:
    """Scenes per world for ``num_envs`` scenes of ``objects`` objects each."""
    return max(1, SHARD_OBJECTS // max(objects, 1), -(-num_envs // MAX_WORLDS))


def check_num_envs(num_envs: object) -> int:
    """``num_envs`` as an int in [1, MAX_ENVS], else a ValueError naming it."""
    if isinstance(num_envs, bool) or not isinstance(num_envs, int):
        raise ValueError(f"num_envs must be an int, got {num_envs!r}")
    if not 1 <= num_envs <= MAX_ENVS:
        raise ValueError(
            f"num_envs must be in [1, {MAX_ENVS}], got {num_envs} (the cap: see "
            "sgc_env.envs.vector.batch.MAX_ENVS)"
        )
    return num_envs


class Batch:
    """The sub-envs of one batch and their worlds (see the module docstring)."""

    def __init__(
        self,
        num_envs: int,
        env_class: type[SGCEnv],
        kwargs: dict[str, Any],
        *,
        max_episode_steps: int | None = None,
        env_id: str | None = None,
    ) -> None:
        n = check_num_envs(num_envs)
        if kwargs.get("render_mode") is not None:
            raise ValueError("render_mode: the batched env does not render; use a single env")
        frequency = int(kwargs.get("sim_frequency", 240))
        self._envs: list[SGCEnv] = []
        self.closed = False
        self.props = PropWorld(frequency)  # never stepped
        self.worlds = [SharedWorld(frequency, self.props)]
        try:
            self._envs.append(env_class(**kwargs, world=self.worlds[0]))
            per_world = scenes_per_world(n, len(self._envs[0].scenario.bodies))
            for i in range(1, n):
                if i % per_world == 0:
                    self.worlds.append(SharedWorld(frequency, self.props))
                self._envs.append(env_class(**kwargs, world=self.worlds[-1]))
        except BaseException:
            self.close()
            raise
        first = self._envs[0]
        self.substeps = first.substeps
        self.action_shape: tuple[int, ...] = first._action_shape
        self.limit = (
            None if max_episode_steps is None or max_episode_steps == -1 else int(max_episode_steps)
        )
        self.env_id = env_id
        self.elapsed = np.zeros(n, dtype=np.int64)
        fast = env_class is SGCEnv and n >= FAST_MIN_ENVS
        self.fast = BatchTask(self._envs) if fast else None
        self._behind = False  # the sub-env objects lag the fast path's arrays
        self._handed = False  # the sub-envs were handed out: reload the arrays from them

    def __len__(self) -> int:
        return len(self._envs)

    @property
    def envs(self) -> list[SGCEnv]:
        """The sub-envs, up to date (read them through this property each time: between
        calls the fast path keeps their per-step state in its arrays)."""
        fast = self.fast
        if fast is not None:
            if self._behind:
                for i in range(len(self._envs)):
                    fast.sync(i)
                self._behind = False
            self._handed = True
        return self._envs

    def reset_one(
        self, i: int, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[Any, dict[str, Any]]:
        """Reset sub-env ``i`` (refusing an episode its time limit would cut short)."""
        env = self._envs[i]
        try:
            obs, info = env.reset(seed=seed, options=options)
        except ValueError as err:  # a refused reset changes nothing (the env's own rule)
            raise ValueError(f"sub-env {i}: {err}") from err
        if self.fast is not None:
            self.fast.load(i)
        if self.env_id is not None:
            check_episode_length(self.env_id, self.limit, env.max_steps)
        self.elapsed[i] = 0
        return obs, dict(info)

    def clip(self, actions: Any, indices: list[int]) -> list[list[float]]:
        """Each listed sub-env's action row, clipped; errors name the sub-env."""
        return self.clip_rows(actions, indices).tolist()

    def clip_rows(self, actions: Any, indices: list[int]) -> np.ndarray:
        """:meth:`clip` as an array (rows, action) of the action's dtype."""
        a = actions if type(actions) is np.ndarray else np.asarray(actions)
        shape = (len(self._envs), *self.action_shape)
        if a.shape != shape:
            raise ValueError(f"actions have shape {a.shape}, expected {shape} (num_envs, action)")
        rows = a if len(indices) == len(self._envs) else a[indices]  # sorted, distinct indices
        if a.dtype.kind in "fiu" and np.isfinite(rows).all():
            return np.minimum(np.maximum(rows, -1), 1)  # as clip_action, for all rows at once
        out = []  # something is wrong: find the first bad row with the single env's check
        for i in indices:
            try:
                out.append(clip_action(a[i], self.action_shape))
            except (TypeError, ValueError) as err:
                raise type(err)(f"sub-env {i}: {err}") from None
        return np.array(out)

    def step_fast(
        self, indices: list[int], actions: Any
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, dict[int, list[GoalEvent]]]:
        """:meth:`step` by the fast path (plain ``SGCEnv`` sub-envs): rewards, terminated and
        truncated over all sub-envs (rows not listed hold stale values: reset them next) and
        the goal events by sub-env; observations and records in ``fast.obs`` / ``fast.rec``."""
        fast = self.fast
        assert fast is not None
        values = self.clip_rows(actions, indices).astype(np.float64)
        if self._handed:  # a sub-env may have been pushed or changed: start from the objects
            for i in range(len(self._envs)):
                fast.load(i, record=False)
            self._handed = False
        with collector_paused():
            rewards, terminated, at_limit, events = fast.step(indices, values)
        self._behind = True
        truncated = ~terminated & at_limit
        if len(indices) == len(self._envs):  # sorted, distinct indices: every sub-env
            self.elapsed += 1
        else:
            self.elapsed[indices] += 1
        if self.limit is not None:
            truncated |= self.elapsed >= self.limit
        return rewards, terminated, truncated, events

    def step(self, indices: list[int], values: list[list[float]]) -> list[StepResult]:
        """One control step of the listed sub-envs (their clipped actions) in one world step;
        the time limit (TimeLimit's rule: truncate once ``elapsed >= limit``) applied."""
        with collector_paused():
            return self._step(indices, values)

    def _step(self, indices: list[int], values: list[list[float]]) -> list[StepResult]:
        envs = self._envs
        by_world: dict[int, list[Any]] = {}
        for i, v in zip(indices, values, strict=True):
            d, moves = envs[i]._drives(v)
            by_world.setdefault(envs[i].sim.client, []).extend(d)
            if moves:  # props: where the step leaves them (once, see BatchTask.sync)
                for uid, spot in moves[-1]:
                    envs[i].sim.move(uid, spot)
        for world in self.worlds:
            if world.client in by_world:
                world.sim.step_bodies(by_world[world.client])
        results = []
        limit, elapsed = self.limit, self.elapsed
        for i, v in zip(indices, values, strict=True):
            obs, reward, terminated, truncated, info = envs[i]._finish_step(v)
            elapsed[i] += 1
            if limit is not None and elapsed[i] >= limit:
                truncated = True
            results.append((obs, reward, terminated, truncated, info))
        return results

    def close(self) -> None:
        """Close every sub-env and free the client (idempotent)."""
        for env in self._envs:
            env.close()
        for world in self.worlds:
            world.close()
        self.props.close()
        self.closed = True
