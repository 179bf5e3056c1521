"""The expert through every kind of vector env, in-process and behind processes.

One accessor (:mod:`baselines.common.sub_envs`) serves all four; the expert must meet its goals the
same way on each (position errors at the goal ticks ~1e-15 m, far inside any tolerance).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import gymnasium as gym
import numpy as np
import pytest
from stable_baselines3.common.vec_env import DummyVecEnv, SubprocVecEnv

import sgc_env  # noqa: F401  (registers the ids)
from baselines import SGCExpert
from baselines.common.sub_envs import base_env
from baselines.policies import make_policy


def _two(kind: type) -> Callable[[str], Any]:
    # "sgc_env:<id>" imports sgc_env in a fresh worker process (forkserver) before making it
    return lambda env_id: kind([lambda: gym.make(f"sgc_env:{env_id}")] * 2)


VECTORS = {
    "DummyVecEnv": _two(DummyVecEnv),
    "SubprocVecEnv": _two(SubprocVecEnv),
    "SyncVectorEnv": _two(gym.vector.SyncVectorEnv),
    "AsyncVectorEnv": _two(gym.vector.AsyncVectorEnv),
}


def _goal_errors(venv: Any, policy: Any, seeds: list[int]) -> list[float]:
    """Run both sub-envs through one episode; the position errors of every goal reached."""
    gym_api = isinstance(venv, gym.vector.VectorEnv)
    if gym_api:
        obs, _ = venv.reset(seed=seeds)
    else:
        venv.seed(seeds[0])
        obs = venv.reset()
    errors: list[float] = []
    done = np.zeros(2, dtype=bool)
    starts = np.ones(2, dtype=bool)
    while not done.all():
        action, _ = policy.predict(obs, episode_start=starts)
        starts[:] = False
        if gym_api:
            obs, _, term, trunc, info = venv.step(action)
            ended = term | trunc
            mask = info.get("_goal_reached", np.zeros(2, dtype=bool))
            events = [info["goal_reached"][i] if mask[i] else [] for i in range(2)]
        else:
            obs, _, ended, infos = venv.step(action)
            events = [i.get("goal_reached", []) for i in infos]
        # a sub-env that finished first auto-resets: count only each one's first episode
        errors += [g["position_error"] for i in range(2) if not done[i] for g in events[i]]
        done |= ended
    return errors


@pytest.mark.parametrize("kind", list(VECTORS))
def test_expert_meets_goals_on_every_vector_env(kind: str) -> None:
    venv = VECTORS[kind]("SGCIntercept-v1")
    try:
        assert base_env(venv, 1).scenario.name == "intercept"
        errors = _goal_errors(venv, SGCExpert(venv), [3, 4])
    finally:
        venv.close()
    assert len(errors) == 2 * 2  # two goals per episode, two sub-envs
    assert max(errors) < 1e-9


@pytest.mark.parametrize("kind", ["SubprocVecEnv", "AsyncVectorEnv"])
def test_episode_expert_reads_each_process_scenario(kind: str) -> None:
    """Random scenarios differ per sub-env; the per-episode expert reads each one's model."""
    venv = VECTORS[kind]("SGCPoint-v1")
    try:
        errors = _goal_errors(venv, make_policy("expert", venv), [5, 6])
    finally:
        venv.close()
    assert len(errors) == 2 * 3
    assert max(errors) < 1e-9


def test_not_an_sgc_env_is_named() -> None:
    venv = gym.vector.SyncVectorEnv([lambda: gym.make("CartPole-v1")])
    with pytest.raises(TypeError, match="not an SGC environment"):
        SGCExpert(venv)
    venv.close()
