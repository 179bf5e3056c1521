"""The planner's view of an env's current state: the same bits as the planner's own version,
through single, Gymnasium-batched and SB3-batched envs, and planner policies acting on it."""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np
import pytest

import sgc_env  # noqa: F401  (registers the ids)
from baselines import SGCExpert
from baselines.common.planner_view import (
    OnPlannerView,
    last_observation,
    observed_view,
    planner_observation,
)
from baselines.policies import make_policy


def _flat(observation: object) -> np.ndarray:
    return observation["observation"] if isinstance(observation, dict) else observation  # type: ignore[index]


@pytest.mark.parametrize("env_id", ["SGCRod-v1", "SGCThreeRods-v2", "SGCPointGoal-v1"])
def test_single_env_hands_out_the_planner_versions_observation(env_id: str) -> None:
    """Step for step (pushes included), the learner's id's planner view is, bit for bit, the
    observation of the same id made with observation='planner'."""
    learner, planner = gym.make(env_id), gym.make(env_id, observation="planner")
    _, _ = learner.reset(seed=4)
    theirs, _ = planner.reset(seed=4)
    assert observed_view(learner) == "learner" and observed_view(planner) == "planner"
    rng = np.random.default_rng(0)
    for tick in range(40):
        mine = planner_observation(learner)
        assert mine.dtype == np.float32 and np.array_equal(mine, _flat(theirs)), tick
        if tick == 20:
            learner.unwrapped.apply_impulse(0, [0.1, 0.0, 0.0])
            theirs = planner.unwrapped.apply_impulse(0, [0.1, 0.0, 0.0])
            continue
        action = rng.uniform(-0.3, 0.3, learner.action_space.shape).astype(np.float32)
        learner.step(action)
        theirs = planner.step(action)[0]
    learner.close()
    planner.close()


@pytest.mark.parametrize("num_envs", [2, 12])  # the per-sub-env path and the numpy fast path
def test_batched_env_hands_out_one_planner_row_per_sub_env(num_envs: int) -> None:
    """gym.make_vec of a learner's id: the rows equal the planner version's batched
    observations through autoresets (short point episodes end inside the run)."""
    make = gym.make_vec
    learner = make("SGCPoint-v1", num_envs, vectorization_mode="vector_entry_point")
    planner = make("SGCPoint-v1", num_envs, vectorization_mode="vector_entry_point",
                   observation="planner")  # fmt: skip
    learner.reset(seed=7)
    theirs, _ = planner.reset(seed=7)
    rng = np.random.default_rng(1)
    ended, resets = 0, 0
    for tick in range(220):
        if tick % 11 == 0 or ended:
            assert np.array_equal(planner_observation(learner), theirs), tick
        actions = rng.uniform(-0.1, 0.1, learner.action_space.shape).astype(np.float32)
        _, _, terminated, truncated, _ = learner.step(actions)
        theirs, _, t2, u2, _ = planner.step(actions)
        assert np.array_equal(terminated, t2) and np.array_equal(truncated, u2)
        ended = int(np.sum(terminated | truncated))
        resets += ended
    assert resets > 0 and np.array_equal(planner_observation(learner), theirs)
    learner.close()
    planner.close()


def _vector(kind: str) -> Any:
    from stable_baselines3.common.vec_env import DummyVecEnv, SubprocVecEnv

    from baselines.agents.sb3_vec_env import make_sgc_vec

    if kind == "batched":
        return make_sgc_vec("SGCRod-v1", 2, 5, {}, "batched")
    # "sgc_env:<id>" imports sgc_env in a fresh worker process before making it
    make = {"DummyVecEnv": DummyVecEnv, "SubprocVecEnv": SubprocVecEnv,
            "AsyncVectorEnv": gym.vector.AsyncVectorEnv}[kind]  # fmt: skip
    return make([lambda: gym.make("sgc_env:SGCRod-v1")] * 2)


@pytest.mark.parametrize("kind", ["DummyVecEnv", "batched", "SubprocVecEnv", "AsyncVectorEnv"])
def test_vector_envs_in_and_out_of_process_hand_out_planner_rows(kind: str) -> None:
    pytest.importorskip("stable_baselines3")
    vec = _vector(kind)
    if isinstance(vec, gym.vector.VectorEnv):
        observations, _ = vec.reset(seed=5)
    else:
        vec.seed(5)
        observations = vec.reset()
    rows = planner_observation(vec)
    single = gym.make("SGCRod-v1", observation="planner")
    assert rows.shape == (2, single.observation_space.shape[0])
    for i in range(2):
        assert np.array_equal(rows[i], single.reset(seed=5 + i)[0])
    assert observed_view(vec) == "learner"
    assert np.array_equal(last_observation(vec), observations)
    policy = make_policy("expert", vec)  # the view is read across processes too
    reference = make_policy("expert", gym.make("SGCRod-v1", observation="planner"))
    assert np.array_equal(policy.predict(observations)[0], reference.predict(rows)[0])
    with pytest.raises(ValueError, match="not the one its env last returned"):
        policy.predict(observations[::-1])  # the sub-envs' rows swapped
    vec.close()


def test_make_policy_puts_the_expert_on_the_planner_view() -> None:
    """On a learner's id the expert acts on the env's planner view: the same actions as on the
    planner's version, every goal met exactly; a stray observation shape is refused."""
    learner, planner = gym.make("SGCRod-v1"), gym.make("SGCRod-v1", observation="planner")
    policy = make_policy("expert", learner)
    reference = make_policy("expert", planner)
    obs, _ = learner.reset(seed=2)
    theirs, _ = planner.reset(seed=2)
    errors = []
    done = False
    while not done:
        action, _ = policy.predict(obs)
        expected, _ = reference.predict(theirs)
        assert np.array_equal(action, expected)
        obs, _, terminated, truncated, info = learner.step(action)
        theirs = planner.step(expected)[0]
        errors += [event["position_error"] for event in info.get("goal_reached", [])]
        done = terminated or truncated
    assert errors and max(errors) < 1e-9
    with pytest.raises(ValueError, match="shape"):
        policy.predict(theirs)  # the planner's observation handed to the learner's env's policy
    learner.close()
    planner.close()


def test_on_planner_view_puts_an_observation_only_policy_on_the_learner_view() -> None:
    """``SGCExpert(model=...)`` reads observations only: OnPlannerView hands it the env's
    planner view, under the same check of the observation as the expert's own."""
    learner, planner = gym.make("SGCRod-v1"), gym.make("SGCRod-v1", observation="planner")
    obs, _ = learner.reset(seed=2)
    theirs, _ = planner.reset(seed=2)
    policy = OnPlannerView(SGCExpert(model=SGCExpert(planner).model), learner)
    assert np.array_equal(policy.predict(obs)[0], SGCExpert(planner).predict(theirs)[0])
    learner.step(policy.predict(obs)[0])
    with pytest.raises(ValueError, match="not the one its env last returned"):
        policy.predict(obs)  # stale: the env has stepped since
    learner.close()
    planner.close()
