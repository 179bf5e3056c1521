"""The newest version of every id: the learner's view and the tracking reward by default, the
expert still exact on them through the planner's view, the batched env bit-identical."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import sgc_env
from baselines import SGCExpert
from baselines.evaluation.harness import evaluate
from baselines.policies import make_policy, needs_planner_view


@pytest.mark.parametrize("env_id", sgc_env.ENV_IDS)
def test_newest_versions_default_to_the_learner_view(env_id: str) -> None:
    env = gym.make(env_id)
    assert env.unwrapped.observation_view == "learner"
    space = env.observation_space
    box = space["observation"] if isinstance(space, gym.spaces.Dict) else space
    assert box.dtype == np.float32 and np.all(np.abs(box.low) <= 3) and np.all(box.high <= 3)
    if "Goal" not in env_id:
        assert env.unwrapped.reward_mode == "tracking"
    env.close()


@pytest.mark.parametrize("env_id", ["SGCRod-v1", "SGCThreeRods-v2", "SGCInterceptRandom-v1"])
def test_the_expert_is_exact_on_the_newest_versions(env_id: str) -> None:
    """The harness gives the expert the planner's view of the same scenes: every goal met to
    1e-9 m and rad."""
    result = evaluate("expert", env_id, episodes=1, seed=3)
    assert result.summary["success_rate"] == 1.0
    assert result.summary["position_error_max"] < 1e-9
    orientation = result.summary["orientation_error_max"]
    assert np.isnan(orientation) or orientation < 1e-9


def test_the_expert_reads_the_planner_view_itself() -> None:
    """By hand, as make_policy builds it, the expert on the learner's view acts on the env's
    planner view (tests/baselines/controllers/test_expert.py); the harness needs it."""
    env = gym.make("SGCRod-v1")
    obs, _ = env.reset(seed=0)
    by_hand, _ = SGCExpert(env).predict(obs)
    planner = gym.make("SGCRod-v1", observation="planner")
    theirs, _ = planner.reset(seed=0)
    assert np.array_equal(by_hand, SGCExpert(planner).predict(theirs)[0])
    assert np.array_equal(make_policy("expert", env).predict(obs)[0], by_hand)
    assert needs_planner_view("expert") and not needs_planner_view("random")
    env.close()
    planner.close()


def test_the_planner_view_has_the_same_scenes_dynamics_and_reward() -> None:
    """SGCRod-v1 with observation='planner' differs from SGCRod-v1 in its observation only:
    the same rewards and planner state, bit for bit."""
    learner = gym.make("SGCRod-v1")
    planner = gym.make("SGCRod-v1", observation="planner")
    learner.reset(seed=11)
    planner.reset(seed=11)
    rng = np.random.default_rng(0)
    for _ in range(40):
        action = rng.uniform(-0.2, 0.2, learner.action_space.shape).astype(np.float32)
        ra, rb = learner.step(action), planner.step(action)
        assert ra[1] == rb[1] and np.array_equal(learner.unwrapped.planner_observation(), rb[0])
    learner.close()
    planner.close()


def test_tracking_reward_is_in_its_range_and_pays_the_expert_near_its_maximum() -> None:
    env = gym.make("SGCRod-v1", observation="planner")
    expert = SGCExpert(env)
    obs, _ = env.reset(seed=2)
    rewards = []
    done = False
    while not done:
        action, _ = expert.predict(obs)
        obs, reward, terminated, truncated, info = env.step(action)
        if "goal_reached" not in info:
            rewards.append(reward)
        done = terminated or truncated
    rewards_arr = np.array(rewards)
    assert np.all(rewards_arr >= 0.0) and np.all(rewards_arr <= 2.01)
    assert np.median(rewards_arr) > 1.8  # two tracks, on schedule but for the smooth starts
    env.close()
