"""Goal-conditioned variant for hindsight relabelling (SB3's HerReplayBuffer).

Dict observation:

| key | size | meaning |
|---|---|---|
| observation | as SGCEnv | the full flat observation of :class:`SGCEnv` (bodies and goal data) |
| achieved_goal | 4 | tracked point of body 0 and the current time |
| desired_goal | 4 | nail of body 0's current position goal and that goal's time (the deadline) |

A goal is met when the point is within ``tolerance`` m of the nail *on the goal's tick*
(|time difference| below half a control period): reward 0, else -1 (sparse, vectorised in
:meth:`compute_reward`). The step reward is ``compute_reward(achieved after the step, desired
before it, info)``, the same call HER makes, so relabelled rewards agree with the env's own.
A failure (``terminated``) also charges -1 for every step the episode had left
(``info["failure_charge"]``, read by :meth:`compute_reward` so relabelled terminal steps keep
it): otherwise leaving the workspace early would end the stream of -1 and pay. Physics,
actions, termination and truncation are those of :class:`SGCEnv`; the ``reward=`` modes of
:class:`SGCEnv` do not apply (a ``ValueError`` says so).
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np

from sgc_env.defaults import POSITION_TOLERANCE
from sgc_env.envs.sgc_env import OBS_BOUND, SGCEnv, StepInfo

__all__ = ["GoalRewardAccess", "SGCGoalEnv"]


class SGCGoalEnv(SGCEnv):
    """:class:`SGCEnv` with a Dict observation (observation, achieved_goal, desired_goal)."""

    def __init__(self, *args: Any, tolerance: float = POSITION_TOLERANCE, **kwargs: Any) -> None:
        if kwargs.get("reward") is not None:
            raise ValueError(
                "reward: the goal-conditioned env's reward is its sparse goal reward "
                "(compute_reward); reward modes apply to SGCEnv ids only"
            )
        super().__init__(*args, **kwargs)
        del self._init_kwargs["reward"]  # the base mode is unused here; pickles re-make it
        self._init_kwargs["tolerance"] = tolerance
        if not self.task.has_position[0]:
            raise ValueError("the goal-conditioned env needs a position track on body 0")
        self.tolerance = float(tolerance)
        box = gym.spaces.Box(-OBS_BOUND, OBS_BOUND, (4,), np.float32)
        flat = self.observation_space  # the view's
        self.observation_space = gym.spaces.Dict(
            {
                "observation": flat,
                "achieved_goal": box,
                "desired_goal": box,
            }
        )

    def _dict_obs(self) -> dict[str, np.ndarray]:
        return {
            "observation": self._obs.copy(),
            "achieved_goal": self.task.achieved_goal(0),
            "desired_goal": self.task.desired_goal(0),
        }

    def reset(  # type: ignore[override]  # a Dict observation where SGCEnv has a Box
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, np.ndarray], StepInfo]:
        _, info = super().reset(seed=seed, options=options)
        self._last = self._dict_obs()
        return self._last, info

    def step(  # type: ignore[override]  # a Dict observation where SGCEnv has a Box
        self, action: np.ndarray
    ) -> tuple[dict[str, np.ndarray], float, bool, bool, StepInfo]:
        return super().step(action)  # type: ignore[return-value]  # via _finish_step below

    def _finish_step(
        self, values: list[float]
    ) -> tuple[dict[str, np.ndarray], float, bool, bool, StepInfo]:
        desired = self._last["desired_goal"]
        _, _, terminated, truncated, info = super()._finish_step(values)
        if terminated:
            info["failure_charge"] = float(self.max_steps - self._tick)
        obs = self._dict_obs()
        reward = float(self.compute_reward(obs["achieved_goal"], desired, info))
        self._last = obs
        return obs, reward, terminated, truncated, info

    def restore_state(self, state: Any) -> dict[str, np.ndarray]:  # type: ignore[override]
        super().restore_state(state)
        self._last = self._dict_obs()
        return self._last

    def __setstate__(self, state: dict[str, Any]) -> None:
        super().__setstate__(state)
        self._last = self._dict_obs()

    def compute_reward(
        self, achieved_goal: np.ndarray, desired_goal: np.ndarray, info: Any
    ) -> np.ndarray:
        """0 where the point is on the nail on the goal's tick, else -1, minus the failure charge
        of a terminal step; any leading shape (``info``: one dict, or one per leading entry)."""
        a = np.asarray(achieved_goal, dtype=np.float64)
        d = np.asarray(desired_goal, dtype=np.float64)
        dist = np.linalg.norm(a[..., :3] - d[..., :3], axis=-1)
        on_time = np.abs(a[..., 3] - d[..., 3]) < 0.5 * self.dt
        reward = np.where((dist <= self.tolerance) & on_time, 0.0, -1.0)
        if isinstance(info, dict):
            reward = reward - info.get("failure_charge", 0.0)
        elif info is not None:
            charges = [i.get("failure_charge", 0.0) if isinstance(i, dict) else 0.0
                       for i in np.asarray(info, dtype=object).reshape(-1)]  # fmt: skip
            reward = reward - np.reshape(charges, reward.shape)
        return reward.astype(np.float32)


class GoalRewardAccess(gym.Wrapper, gym.utils.RecordConstructorArgs):
    """Outermost wrapper of the registered goal id: exposes ``compute_reward``.

    Gymnasium's wrappers (``TimeLimit``, ``OrderEnforcing``) do not forward attributes, and
    SB3's ``check_env`` (like other GoalEnv tools) calls ``env.compute_reward`` on the env it
    is given. The registry adds this wrapper after ``TimeLimit``.
    """

    def __init__(self, env: gym.Env) -> None:
        gym.utils.RecordConstructorArgs.__init__(self)
        gym.Wrapper.__init__(self, env)

    def compute_reward(
        self, achieved_goal: np.ndarray, desired_goal: np.ndarray, info: Any
    ) -> np.ndarray:
        """The base env's :meth:`SGCGoalEnv.compute_reward`."""
        return self.env.unwrapped.compute_reward(achieved_goal, desired_goal, info)  # type: ignore[attr-defined]
