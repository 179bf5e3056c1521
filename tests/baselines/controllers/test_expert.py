"""The analytic expert inside PyBullet: exact, punctual, within limits, robust to a push."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import sgc_env
from baselines.controllers.expert import SGCExpert
from baselines.evaluation.harness import goal_rows, run_episode

EXACT = 1e-9
RANDOM_SEEDS = 100  # per random env: SGCPoint-v0 and SGCRod-v0 give 200 scenarios


def _assert_exact(record, env_id: str) -> None:
    assert not record.terminated
    events = [e for info in record.infos for e in info.get("goal_reached", [])]
    assert events, "no goal was reached"
    for e in events:
        assert e["position_error"] is None or e["position_error"] <= EXACT, (env_id, e)
        assert e["orientation_error"] is None or e["orientation_error"] <= EXACT, (env_id, e)
    for row in goal_rows(record, env_id, "expert"):
        # closest approach on the goal's own tick (offsets in seconds)
        assert row["position_closest_offset"] is None or abs(row["position_closest_offset"]) < 1e-9


def _run(env, seed: int):
    expert = SGCExpert(env)
    record = run_episode(expert, env, seed=seed, keep_infos=True)
    return record


@pytest.mark.parametrize("env_id", sgc_env.ENV_IDS)
def test_expert_is_exact_on_every_registered_env(env_id):
    env = gym.make(env_id)
    record = _run(env, seed=7)
    env.close()
    _assert_exact(record, env_id)


@pytest.mark.parametrize("env_id", ["SGCPoint-v0", "SGCRod-v0"])
def test_expert_is_exact_on_random_scenarios_within_the_action_limits(env_id):
    env = gym.make(env_id)
    expert = SGCExpert(env)
    for seed in range(RANDOM_SEEDS):
        obs, _ = env.reset(seed=1000 + seed)
        done = False
        while not done:
            action, _ = expert.predict(obs)
            assert np.max(np.abs(action)) < 1.0, (env_id, seed)  # never saturated
            obs, _, terminated, truncated, info = env.step(action)
            done = terminated or truncated
            assert not terminated, (env_id, seed)
            for e in info.get("goal_reached", []):
                assert e["position_error"] is None or e["position_error"] <= EXACT, (seed, e)
                assert e["orientation_error"] is None or e["orientation_error"] <= EXACT, (seed, e)
    env.close()


def test_a_push_mid_course_is_absorbed_and_the_next_goal_is_still_exact():
    env = gym.make("SGCRod-v0")
    base = env.unwrapped
    expert = SGCExpert(env)
    obs, _ = env.reset(seed=3)
    first_goal = min(g.time for g in base.scenario.bodies[0].goals)
    push_tick = int(round(0.5 * first_goal / base.dt))
    events, pushed_deviation = [], None
    for tick in range(base.max_steps):
        if tick == push_tick:
            before = obs.copy()
            obs = base.apply_impulse(0, linear=(0.3, -0.2, 0.25), angular=(0.004, 0.0, -0.003))
            pushed_deviation = np.abs(obs - before).max()
        action, _ = expert.predict(obs)
        obs, _, terminated, truncated, info = env.step(action)
        events += info.get("goal_reached", [])
        if terminated or truncated:
            break
    env.close()
    assert pushed_deviation is not None and pushed_deviation > 0.1
    assert not terminated
    assert events and events[0]["time"] == pytest.approx(first_goal)
    for e in events:
        assert e["position_error"] <= EXACT and e["orientation_error"] <= EXACT


def test_expert_reads_goal_conditioned_observations():
    env = gym.make("SGCPointGoal-v0")
    obs, _ = env.reset(seed=1)
    action, state = SGCExpert(env).predict(obs)
    assert action.shape == env.action_space.shape and state is None


def test_expert_rejects_a_wrong_observation():
    env = gym.make("SGCPoint-v0")
    with pytest.raises(ValueError, match="observation has shape"):
        SGCExpert(env).predict(np.zeros(5))
    obs, _ = env.reset(seed=0)
    obs[3] = np.nan
    with pytest.raises(ValueError, match="non-finite"):
        SGCExpert(env).predict(obs)


def test_without_the_torque_correction_goals_stay_exact():
    env = gym.make("SGCThreeRods-v1")
    record = run_episode(SGCExpert(env, refine=False), env, seed=7, keep_infos=True)
    env.close()
    _assert_exact(record, "SGCThreeRods-v1")


def test_actions_from_tuples_equal_actions_from_arrays():
    env = gym.make("SGCThreeRods-v1")
    model = SGCExpert(env).model
    env.close()
    rng = np.random.default_rng(0)
    forces, torques = rng.normal(size=(3, 3)) * 50.0, rng.normal(size=(3, 3))
    quats = rng.normal(size=(3, 4))
    quats /= np.linalg.norm(quats, axis=1, keepdims=True)
    from_arrays = model.action_from_wrenches(forces, torques, quats)
    from_tuples = model.action_from_wrenches(
        [tuple(f) for f in forces.tolist()], [tuple(t) for t in torques.tolist()],
        [tuple(q) for q in quats.tolist()],
    )
    assert from_arrays.dtype == np.float64 and np.array_equal(from_arrays, from_tuples)
    assert np.max(np.abs(from_arrays)) <= 1.0
