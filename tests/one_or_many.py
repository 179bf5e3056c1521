"""One set of test cases for the single and the batched env: ``gym.make_vec(id, 1)`` seen as
a single env, its numpy path forced (a batch of one would otherwise step by each sub-env's own
code). Used through the ``make_env`` fixture of ``conftest.py``."""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np

from sgc_env.envs.vector import batch as batch_module


class BatchOfOne(gym.Env):
    """The single-env API over a batched env of one sub-env (within an episode: after one
    ends, call ``reset`` as on a single env)."""

    def __init__(self, env_id: str, **kwargs: Any) -> None:
        saved = batch_module.FAST_MIN_ENVS
        batch_module.FAST_MIN_ENVS = 1
        try:
            self.vec = gym.make_vec(env_id, 1, vectorization_mode="vector_entry_point", **kwargs)
        finally:
            batch_module.FAST_MIN_ENVS = saved
        assert self.vec.unwrapped._batch.fast is not None
        self.observation_space = self.vec.single_observation_space
        self.action_space = self.vec.single_action_space

    @property
    def unwrapped(self) -> Any:  # type: ignore[override]
        return self.vec.unwrapped.envs[0]

    @staticmethod
    def _row(info: dict[str, Any]) -> dict[str, Any]:
        return {k: v[0] for k, v in info.items() if not k.startswith("_") and info[f"_{k}"][0]}

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None) -> Any:
        obs, info = self.vec.reset(seed=seed, options=options)
        return obs[0], self._row(info)

    def step(self, action: Any) -> Any:
        obs, reward, terminated, truncated, info = self.vec.step(np.asarray(action)[None])
        return obs[0], float(reward[0]), bool(terminated[0]), bool(truncated[0]), self._row(info)

    def close(self) -> None:
        self.vec.close()
