"""SGCPointGoal-v1's goals carry their time: HER's relabelled goal is "this point at this tick".

The desired goal holds the goal's time and the achieved goal the current time, so hindsight
relabelling with a later achieved goal asks for that point *at that tick*: being at the point
a tick early or late is no success. These tests fill SB3's ``HerReplayBuffer`` from the env
(no learning) and check what it samples against the env's own ``compute_reward``.
"""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

pytest.importorskip("stable_baselines3")


@pytest.fixture(scope="module")
def her_batch():
    from stable_baselines3 import HerReplayBuffer
    from stable_baselines3.common.vec_env import DummyVecEnv

    vec = DummyVecEnv([lambda: gym.make("SGCPointGoal-v1")])
    vec.seed(3)
    buffer = HerReplayBuffer(
        5_000, vec.observation_space, vec.action_space, env=vec, n_sampled_goal=4,
        goal_selection_strategy="future",
    )  # fmt: skip
    rng = np.random.default_rng(0)
    obs = vec.reset()
    achieved_times = set()
    for _ in range(2):  # two whole episodes; slow, small actions: the point lingers near spots
        done = np.array([False])
        while not done[0]:
            action = (0.05 * rng.standard_normal((1, 3))).astype(np.float32)
            next_obs, reward, done, infos = vec.step(action)
            real_next = infos[0]["terminal_observation"] if done[0] else next_obs
            achieved = np.asarray(real_next["achieved_goal"]).reshape(-1)
            achieved_times.add(round(float(achieved[3]), 4))
            stored_next = {k: np.asarray(v).reshape(1, -1) for k, v in real_next.items()}
            buffer.add(obs, stored_next, action, reward, done, infos)
            obs = next_obs
    base = vec.envs[0].unwrapped
    np.random.seed(0)  # noqa: NPY002 - HerReplayBuffer samples with numpy's global generator
    return buffer.sample(4_000), base, achieved_times


def test_relabelled_goals_keep_the_time_of_the_step_they_came_from(her_batch) -> None:
    batch, base, achieved_times = her_batch
    desired = batch.observations["desired_goal"].numpy()
    next_achieved = batch.next_observations["achieved_goal"].numpy()
    # every sampled goal's time is a tick the episode reached (relabelled) or a goal's deadline;
    # relabelled ones are the majority (n_sampled_goal 4: 80 %)
    relabelled = np.array([round(float(t), 4) in achieved_times for t in desired[:, 3]])
    assert relabelled.mean() > 0.5
    # "future": the relabelled goal's tick is at or after the transition's own next tick
    later = desired[relabelled, 3] >= next_achieved[relabelled, 3] - 0.5 * base.dt
    assert later.all()


def test_a_relabelled_success_is_the_point_on_its_tick(her_batch) -> None:
    batch, base, _ = her_batch
    desired = batch.observations["desired_goal"].numpy()
    achieved = batch.next_observations["achieved_goal"].numpy()
    rewards = batch.rewards.numpy().ravel()
    expected = base.compute_reward(achieved, desired, [{}] * len(desired))
    charged = rewards < -1.0  # a failure's terminal step also pays for the steps it left
    np.testing.assert_array_equal(rewards[~charged], expected[~charged])
    hits = rewards == 0.0
    assert hits.any(), "relabelling made no success"
    np.testing.assert_array_less(np.abs(achieved[hits, 3] - desired[hits, 3]), 0.5 * base.dt)
    # the same goal one tick later is missed: time is part of the goal
    late = desired[hits].copy()
    late[:, 3] += base.dt
    assert (base.compute_reward(achieved[hits], late, [{}] * int(hits.sum())) == -1.0).all()
    # and some relabelled goals sit on a point the step reached, at another tick: position-only
    # relabelling would have paid those; here they are misses
    near = np.linalg.norm(achieved[:, :3] - desired[:, :3], axis=1) <= base.tolerance
    off_tick = np.abs(achieved[:, 3] - desired[:, 3]) >= 0.5 * base.dt
    assert (near & off_tick).any()
    assert (rewards[near & off_tick & ~charged] == -1.0).all()


def test_the_env_reward_is_compute_reward_of_the_step() -> None:
    env = gym.make("SGCPointGoal-v1")
    obs, _ = env.reset(seed=5)
    for _ in range(30):
        nxt, reward, terminated, truncated, info = env.step(np.zeros(3, np.float32))
        assert nxt["achieved_goal"][3] == pytest.approx(obs["achieved_goal"][3] + env.unwrapped.dt)
        assert reward == env.unwrapped.compute_reward(
            nxt["achieved_goal"], obs["desired_goal"], info
        )
        obs = nxt
