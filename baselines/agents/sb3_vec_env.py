"""SB3 ``VecEnv`` over the batched env: N sub-envs in shared PyBullet worlds, SB3's conventions.

The sub-envs are the batched env's (:mod:`sgc_env.envs.vector.batch`), so each steps exactly as
``gym.make(id)`` inside ``DummyVecEnv`` would; what changes is SB3's side of the contract:
a sub-env that ends is reset in the same step (after the world's physics), its last
observation in ``info["terminal_observation"]`` and ``info["TimeLimit.truncated"]`` set as
SB3's TimeLimit handling expects. ``seed(s)`` seeds sub-env i with ``s + i`` at the next
reset, as DummyVecEnv does. Episode statistics come from ``VecMonitor`` (:func:`make_sgc_vec`
adds it), since there is no per-env ``Monitor``. ``envs`` lists the sub-envs, so
:func:`baselines.common.sub_envs.sub_env` and the expert read them as they read DummyVecEnv's.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import gymnasium as gym
import numpy as np
from stable_baselines3.common.env_util import is_wrapped, make_vec_env
from stable_baselines3.common.vec_env import DummyVecEnv, SubprocVecEnv, VecEnv, VecMonitor

from sgc_env import check_env_id
from sgc_env.envs.goal_env import SGCGoalEnv
from sgc_env.envs.sgc_env import SGCEnv
from sgc_env.envs.vector.batch import Batch
from sgc_env.envs.vector.infos import row_infos

__all__ = ["VEC_KINDS", "BatchedVecEnv", "has_batched", "make_sgc_vec"]

VEC_KINDS = ("batched", "dummy", "subproc")


class BatchedVecEnv(VecEnv):
    """``n_envs`` sub-envs of ``env_id`` in shared worlds (see the module docstring)."""

    def __init__(
        self,
        env_id: str,
        n_envs: int = 1,
        env_kwargs: dict[str, Any] | None = None,
        max_episode_steps: int | None = None,
    ) -> None:
        """``env_kwargs`` are ``gym.make``'s (``max_episode_steps`` included)."""
        spec = gym.spec(check_env_id(env_id))
        goal = str(spec.vector_entry_point).endswith("SGCGoalVectorEnv")
        kwargs = {**spec.kwargs, **(env_kwargs or {})}
        limit = kwargs.pop("max_episode_steps", max_episode_steps)
        limit = spec.max_episode_steps if limit is None else limit
        self._batch = Batch(
            n_envs, SGCGoalEnv if goal else SGCEnv, kwargs, max_episode_steps=limit, env_id=env_id
        )
        first = self._batch.envs[0]
        super().__init__(n_envs, first.observation_space, first.action_space)
        self._actions: np.ndarray | None = None

    @property
    def envs(self) -> list[SGCEnv]:
        """The sub-envs (up to date when read: see ``Batch.envs``)."""
        return self._batch.envs

    def _stack(self, items: list[Any]) -> Any:
        if isinstance(items[0], dict):
            return {k: np.stack([o[k] for o in items]) for k in items[0]}
        return np.stack(items)

    def reset(self) -> Any:
        obs = []
        for i in range(self.num_envs):
            options = self._options[i] or None
            o, self.reset_infos[i] = self._batch.reset_one(i, self._seeds[i], options)
            obs.append(o)
        self._reset_seeds()
        self._reset_options()
        fast = self._batch.fast
        return self._stack(obs) if fast is None else fast.share()[0]

    def step_async(self, actions: np.ndarray) -> None:
        self._actions = actions

    def step_wait(self) -> tuple[Any, np.ndarray, np.ndarray, list[dict[str, Any]]]:
        batch, n = self._batch, self.num_envs
        indices = list(range(n))
        if batch.fast is not None:
            return self._step_fast(indices)
        values = batch.clip(self._actions, indices)
        obs, infos = [], []
        rewards = np.zeros(n, dtype=np.float32)
        dones = np.zeros(n, dtype=bool)
        for i, (o, reward, terminated, truncated, info) in enumerate(batch.step(indices, values)):
            info = dict(info)
            info["TimeLimit.truncated"] = truncated and not terminated
            if terminated or truncated:
                info["terminal_observation"] = o
                o, self.reset_infos[i] = batch.reset_one(i)
            rewards[i], dones[i] = reward, terminated or truncated
            obs.append(o)
            infos.append(info)
        return self._stack(obs), rewards, dones, infos

    def _step_fast(self, indices: list[int]) -> tuple[Any, np.ndarray, np.ndarray, list[Any]]:
        """:meth:`step_wait` of plain SGC sub-envs: infos are rows of the step's arrays."""
        batch = self._batch
        fast = batch.fast
        assert fast is not None
        rewards, terminated, truncated, events = batch.step_fast(indices, self._actions)
        cut = (truncated & ~terminated).tolist()
        infos = row_infos(fast, events, "TimeLimit.truncated", cut)
        dones = terminated | truncated
        obs, _ = fast.share()  # the resets below write into copies
        for i in np.flatnonzero(dones).tolist():
            infos[i]["terminal_observation"] = obs[i]
            _, self.reset_infos[i] = batch.reset_one(i)
        return fast.obs, rewards.astype(np.float32), dones, infos

    def close(self) -> None:
        self._batch.close()

    def _targets(self, indices: Any) -> list[SGCEnv]:
        return [self.envs[i] for i in self._get_indices(indices)]

    def get_attr(self, attr_name: str, indices: Any = None) -> list[Any]:
        return [getattr(env, attr_name) for env in self._targets(indices)]

    def set_attr(self, attr_name: str, value: Any, indices: Any = None) -> None:
        for env in self._targets(indices):
            setattr(env, attr_name, value)

    def env_method(
        self, method_name: str, *method_args: Any, indices: Any = None, **method_kwargs: Any
    ) -> list[Any]:
        return [
            getattr(env, method_name)(*method_args, **method_kwargs)
            for env in self._targets(indices)
        ]

    def env_is_wrapped(self, wrapper_class: type[gym.Wrapper], indices: Any = None) -> list[bool]:
        return [is_wrapped(env, wrapper_class) for env in self._targets(indices)]

    def get_images(self) -> Sequence[np.ndarray | None]:
        raise NotImplementedError(
            "the batched env does not render (its sub-envs share one world); use --vec dummy"
        )


def has_batched(env_id: str) -> bool:
    """Whether ``env_id`` has the batched env (every SGC id)."""
    entry = gym.spec(check_env_id(env_id)).vector_entry_point
    return isinstance(entry, str) and entry.startswith("sgc_env.envs.vector.vector_env:")


def make_sgc_vec(
    env_id: str,
    n_envs: int,
    seed: int | None = None,
    env_kwargs: dict[str, Any] | None = None,
    vec: str | None = None,
) -> VecEnv:
    """A monitored SB3 VecEnv of ``n_envs`` copies of ``env_id``: ``batched`` (shared worlds; the
    default where the id has it), ``dummy`` or ``subproc`` (single envs, as
    ``make_vec_env``); sub-env i seeded ``seed + i``."""
    if vec is None:
        vec = "batched" if has_batched(env_id) else "dummy"
    if vec not in VEC_KINDS:
        raise ValueError(f"vec: expected one of {list(VEC_KINDS)}, got {vec!r}")
    if vec == "batched" and not has_batched(env_id):
        raise ValueError(f"vec: {env_id} has no batched env; use 'dummy' or 'subproc'")
    if vec != "batched":
        cls = SubprocVecEnv if vec == "subproc" else DummyVecEnv
        # "module:id" makes gym.make import sgc_env first, also in SubprocVecEnv's workers
        module_id = f"sgc_env:{env_id}" if has_batched(env_id) else env_id
        return make_vec_env(
            module_id, n_envs=n_envs, seed=seed, env_kwargs=env_kwargs or None, vec_env_cls=cls
        )
    env = BatchedVecEnv(env_id, n_envs, env_kwargs)
    if seed is not None:
        env.seed(seed)
        for i, sub in enumerate(env.envs):
            sub.action_space.seed(seed + i)  # as make_vec_env does
    return VecMonitor(env)
