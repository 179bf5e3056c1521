"""The batched env as a Gymnasium 1.x ``VectorEnv``: every registered id's vector entry point.

``gym.make_vec(id, num_envs=N, vectorization_mode="vector_entry_point")`` builds N sub-envs
in a few shared PyBullet worlds (:mod:`.batch`); each sub-env's observations, rewards, flags
and goal events equal those of ``gym.make(id)`` with the same seeds and actions, bit for bit
(tests/sgc_env/envs/test_batch.py). Conventions:

- ``single_observation_space`` / ``single_action_space``; batched spaces from Gymnasium;
- next-step autoreset (``metadata["autoreset_mode"]``): the step after a sub-env ends resets
  it, ignoring its action, with reward 0 and both flags False;
- infos are a dict of arrays with ``_key`` masks (Gymnasium's layout);
- ``reset(seed=s)`` seeds sub-env i with ``s + i`` (or takes a list of seeds);
  ``reset(options=...)`` passes the options to every sub-env reset (``options["reset_mask"]``,
  a bool array, resets only those sub-envs);
- ``max_episode_steps`` (the registered bound unless given, -1 for none) truncates as
  Gymnasium's TimeLimit does on a single env.

:func:`make_vec` does the same for every id, the goal-conditioned one included (Gymnasium's
``make_vec`` refuses that id: its spec adds a wrapper).
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space, concatenate, create_empty_array

from ..goal_env import SGCGoalEnv
from ..sgc_env import SGCEnv
from .batch import Batch
from .infos import vector_infos

__all__ = ["SGCGoalVectorEnv", "SGCVectorEnv", "batch_infos", "make_vec"]


def batch_infos(infos: list[dict[str, Any]], indices: list[int], n: int) -> dict[str, Any]:
    """Gymnasium's vector info layout: per key an array over sub-envs plus a ``_key`` mask of
    the sub-envs that reported it (arrays of the value's dtype, else object arrays)."""
    out: dict[str, Any] = {}
    present: dict[str, list[int]] = {}
    for j, info in enumerate(infos):
        for key in info:
            present.setdefault(key, []).append(j)
    for key, js in present.items():
        first = infos[js[0]][key]
        rows = [indices[j] for j in js]
        if len(js) == n and rows == list(range(n)) and isinstance(first, (np.ndarray, float)):
            out[key] = (
                np.stack([info[key] for info in infos])
                if isinstance(first, np.ndarray)
                else np.array([info[key] for info in infos])
            )
            out[f"_{key}"] = np.ones(n, dtype=bool)
            continue
        if isinstance(first, np.ndarray):
            array = np.zeros((n, *first.shape), dtype=first.dtype)
        elif type(first) in (int, float, bool) or isinstance(first, np.number):
            array = np.zeros(n, dtype=type(first))
        else:
            array = np.full(n, None, dtype=object)
        for row, j in zip(rows, js, strict=True):
            array[row] = infos[j][key]
        mask = np.zeros(n, dtype=bool)
        mask[rows] = True
        out[key] = array
        out[f"_{key}"] = mask
    return out


class SGCVectorEnv(VectorEnv):
    """``num_envs`` SGC envs in shared PyBullet worlds (see the module docstring); the other
    keyword arguments are the single env's (``gym.make(id, **kwargs)``)."""

    env_class: type[SGCEnv] = SGCEnv
    metadata = {"autoreset_mode": AutoresetMode.NEXT_STEP, "render_modes": []}

    def __init__(
        self, num_envs: int = 1, *, max_episode_steps: int | None = None, **kwargs: Any
    ) -> None:
        self._batch = Batch(num_envs, self.env_class, kwargs, max_episode_steps=max_episode_steps)
        first = self._batch.envs[0]
        self.num_envs = len(self._batch)
        self.single_observation_space = first.observation_space
        self.single_action_space = first.action_space
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self.action_space = batch_space(self.single_action_space, self.num_envs)
        self.render_mode = None
        self._autoreset = np.zeros(self.num_envs, dtype=bool)
        self._obs: list[Any] = [None] * self.num_envs

    @property
    def envs(self) -> list[SGCEnv]:
        """The sub-envs (read their scenario, layout, ... ; step and reset the vector env)."""
        return self._batch.envs

    def _stack(self, items: list[Any]) -> Any:
        space = self.single_observation_space
        out: Any = create_empty_array(space, len(items))
        return concatenate(space, items, out)

    def reset(
        self,
        *,
        seed: int | list[int | None] | None = None,
        options: dict[str, Any] | None = None,
    ) -> tuple[Any, dict[str, Any]]:
        self._check_open()
        n = self.num_envs
        # The spec is set after construction (gym.make_vec, make_vec): read at reset.
        self._batch.env_id = None if self.spec is None else self.spec.id
        if seed is None or isinstance(seed, int):
            seeds: list[int | None] = [None if seed is None else seed + i for i in range(n)]
        else:
            seeds = list(seed)
            if len(seeds) != n:
                raise ValueError(f"seed: {len(seeds)} seeds for {n} sub-envs")
        options = dict(options or {})
        mask = options.pop("reset_mask", None)
        if mask is None:
            indices = list(range(n))
        else:
            mask = np.asarray(mask)
            if mask.dtype != np.bool_ or mask.shape != (n,):
                raise ValueError(f"options['reset_mask'] must be a bool array of shape ({n},)")
            indices = np.flatnonzero(mask).tolist()
        infos = []
        for i in indices:
            self._obs[i], info = self._batch.reset_one(i, seeds[i], options or None)
            infos.append(info)
            self._autoreset[i] = False
        fast = self._batch.fast
        obs = self._stack(self._obs) if fast is None else fast.share()[0]
        return obs, batch_infos(infos, indices, n)

    def step(self, actions: Any) -> tuple[Any, np.ndarray, np.ndarray, np.ndarray, dict]:
        self._check_open()
        n = self.num_envs
        if self._obs[0] is None:
            raise RuntimeError("call reset() before step() on the batched env")
        resetting = np.flatnonzero(self._autoreset).tolist()
        stepping = np.flatnonzero(~self._autoreset).tolist()
        if self._batch.fast is not None:
            return self._step_fast(actions, stepping, resetting)
        values = self._batch.clip(actions, stepping)
        rewards = np.zeros(n)
        terminated = np.zeros(n, dtype=bool)
        truncated = np.zeros(n, dtype=bool)
        infos: list[dict[str, Any]] = []
        for i, (obs, reward, term, trunc, info) in zip(
            stepping, self._batch.step(stepping, values), strict=True
        ):
            self._obs[i] = obs
            rewards[i], terminated[i], truncated[i] = reward, term, trunc
            infos.append(info)
        for i in resetting:  # after the physics: see sgc_env.envs.vector.batch
            self._obs[i], info = self._batch.reset_one(i)
            infos.append(info)
        self._autoreset = terminated | truncated
        return (
            self._stack(self._obs), rewards, terminated, truncated,
            batch_infos(infos, stepping + resetting, n),
        )  # fmt: skip

    def _step_fast(
        self, actions: Any, stepping: list[int], resetting: list[int]
    ) -> tuple[Any, np.ndarray, np.ndarray, np.ndarray, dict]:
        """:meth:`step` of plain SGC sub-envs: arrays from the batch's shared buffers."""
        batch = self._batch
        rewards, terminated, truncated, events = batch.step_fast(stepping, actions)
        for i in resetting:  # after the physics: see sgc_env.envs.vector.batch
            self._obs[i] = batch.reset_one(i)[0]
        if resetting:
            rewards[resetting] = 0.0
            terminated[resetting] = truncated[resetting] = False
        assert batch.fast is not None
        obs, _ = batch.fast.share()
        infos = vector_infos(batch.fast, events)
        self._autoreset = terminated | truncated
        return obs, rewards, terminated, truncated, infos

    def render(self) -> None:
        raise NotImplementedError(
            "the batched env does not render (its sub-envs share one world); render a single "
            "env made with gym.make(id, render_mode=...)"
        )

    def close_extras(self, **kwargs: Any) -> None:
        self._batch.close()

    def _check_open(self) -> None:
        if self._batch.closed:
            raise RuntimeError("this batched env is closed (close() was called); make a new one")


class SGCGoalVectorEnv(SGCVectorEnv):
    """The batched goal-conditioned env (Dict observations, ``compute_reward``)."""

    env_class = SGCGoalEnv

    def compute_reward(
        self, achieved_goal: np.ndarray, desired_goal: np.ndarray, info: Any
    ) -> np.ndarray:
        """Sub-env 0's :meth:`SGCGoalEnv.compute_reward` (the same for every sub-env)."""
        return self.envs[0].compute_reward(achieved_goal, desired_goal, info)  # type: ignore[attr-defined]


def make_vec(env_id: str, num_envs: int = 1, **kwargs: Any) -> SGCVectorEnv:
    """The batched env of any SGC id (``gym.make_vec``'s vector entry point, which Gymnasium
    refuses for ids with additional wrappers), with the spec's kwargs and episode bound."""
    spec = gym.spec(env_id)
    goal = str(spec.vector_entry_point).endswith("SGCGoalVectorEnv")
    creator = SGCGoalVectorEnv if goal else SGCVectorEnv
    merged = {**spec.kwargs, **kwargs}
    merged.setdefault("max_episode_steps", spec.max_episode_steps)
    env = creator(num_envs, **merged)
    env.spec = spec
    return env
