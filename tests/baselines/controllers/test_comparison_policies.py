"""The comparison controllers on the newest ids: built on an env of the learner's view they
act on its planner view of the state, as on the planner's version of the id."""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np
import pytest

import sgc_env
from baselines.controllers.comparison_policies import (
    DynamicConstraintsController,
    MinimumJerkController,
)

EXACT = 1e-9
FLAT_IDS = [k for k in sgc_env.ENV_IDS if "Goal" not in k]
"""The newest ids with a flat observation (the comparisons read no goal-conditioned Dict)."""


def _episode(env: Any, policy: Any, seed: int) -> tuple[list[np.ndarray], list[dict], bool]:
    """The actions and goal events of one episode, and whether it failed."""
    obs, _ = env.reset(seed=seed)
    actions, events = [], []
    start = True
    while True:
        action, _ = policy.predict(obs, episode_start=np.array([start]))
        start = False
        actions.append(action)
        obs, _, terminated, truncated, info = env.step(action)
        events += info.get("goal_reached", [])
        if terminated or truncated:
            return actions, events, bool(terminated)


@pytest.mark.parametrize("env_id", FLAT_IDS)
def test_minimum_jerk_is_exact_on_the_newest_ids(env_id: str) -> None:
    env = gym.make(env_id)
    _, events, failed = _episode(env, MinimumJerkController(env), seed=3)
    env.close()
    assert not failed and events
    for e in events:
        assert e["position_error"] is None or e["position_error"] <= EXACT, e
        assert e["orientation_error"] is None or e["orientation_error"] <= EXACT, e


@pytest.mark.parametrize("env_id", FLAT_IDS)
def test_dynamic_constraints_acts_as_on_the_planner_version(env_id: str) -> None:
    """Its actions over an episode are, bit for bit, those on the planner's view of the id
    (its goals are met only to its eps: the method's own pathology, not a view's)."""
    learner, planner = gym.make(env_id), gym.make(env_id, observation="planner")
    mine, _, _ = _episode(learner, DynamicConstraintsController(learner), seed=3)
    theirs, _, _ = _episode(planner, DynamicConstraintsController(planner), seed=3)
    learner.close()
    planner.close()
    assert len(mine) == len(theirs)
    assert all(np.array_equal(a, b) for a, b in zip(mine, theirs, strict=True))


def test_minimum_jerk_is_exact_on_a_batched_learner_env() -> None:
    venv = gym.make_vec("SGCRod-v1", num_envs=2, vectorization_mode="vector_entry_point")
    policy = MinimumJerkController(venv)
    obs, _ = venv.reset(seed=4)
    done = np.zeros(2, dtype=bool)
    errors: list[float] = []
    while not done.all():
        action, _ = policy.predict(obs)
        obs, _, terminated, truncated, info = venv.step(action)
        mask = info.get("_goal_reached", np.zeros(2, dtype=bool))
        errors += [
            e["position_error"] for i in np.flatnonzero(mask & ~done)
            for e in info["goal_reached"][i]
        ]  # fmt: skip
        done |= terminated | truncated
    venv.close()
    assert len(errors) == 2 * 3 and max(errors) <= EXACT  # three goals per rod episode


@pytest.mark.parametrize("make", [MinimumJerkController, DynamicConstraintsController])
def test_a_state_other_than_the_envs_is_refused(make: type) -> None:
    env = gym.make("SGCRod-v1")
    policy = make(env)
    obs, _ = env.reset(seed=0)
    action, _ = policy.predict(obs)
    env.step(action)
    with pytest.raises(ValueError, match=f"{make.__name__}: this observation is not the one"):
        policy.predict(obs)  # stale: the env has stepped since
    with pytest.raises(ValueError, match="planner's view's size"):
        policy.predict(env.unwrapped.planner_observation())
    env.close()
