"""The analytic expert inside PyBullet: exact, punctual, within limits, robust to a push; on
every registered id, whichever view it observes, single, batched or wrapped."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import sgc_env
from baselines.controllers.expert import SGCExpert
from baselines.evaluation.harness import goal_rows, run_episode

EXACT = 1e-9
RANDOM_SEEDS = 100  # per random env: SGCPoint-v1 and SGCRod-v1 give 200 scenarios
REGISTERED = [k for k in gym.registry if k.startswith("SGC")]
"""Every registered id, the planner-view versions and the newest (learner-view) ones."""


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


def _assert_goals_exact(events: list[dict], where: object) -> None:
    assert events, ("no goal was reached", where)
    for e in events:
        assert e["position_error"] is None or e["position_error"] <= EXACT, (where, e)
        assert e["orientation_error"] is None or e["orientation_error"] <= EXACT, (where, e)


def test_every_view_of_every_id_is_registered():
    assert set(REGISTERED) == set(sgc_env.ENV_IDS)


@pytest.mark.parametrize("env_id", REGISTERED)
def test_expert_is_exact_on_every_registered_env(env_id):
    """``SGCExpert(gym.make(id))``, built before the first reset: on the learner's view it
    reads the env's planner view of the state itself."""
    env = gym.make(env_id)
    record = _run(env, seed=7)
    env.close()
    _assert_exact(record, env_id)


def _vector_goal_events(venv, policy, seed: int) -> list[list[dict]]:
    """Each sub-env's goal events over its first episode (the batched env resets a finished
    sub-env on the next step; what follows is not counted)."""
    obs, _ = venv.reset(seed=seed)
    n = venv.num_envs
    events: list[list[dict]] = [[] for _ in range(n)]
    done = np.zeros(n, dtype=bool)
    while not done.all():
        action, _ = policy.predict(obs)
        obs, _, terminated, truncated, info = venv.step(action)
        assert not np.any(terminated & ~done), "a sub-env failed"
        mask = info.get("_goal_reached", np.zeros(n, dtype=bool))
        for i in np.flatnonzero(mask & ~done):
            events[i] += list(info["goal_reached"][i])
        done |= terminated | truncated
    return events


@pytest.mark.parametrize("env_id", REGISTERED)
def test_expert_is_exact_on_every_registered_batched_env(env_id):
    venv = gym.make_vec(env_id, num_envs=2, vectorization_mode="vector_entry_point")
    try:
        events = _vector_goal_events(venv, SGCExpert(venv), seed=7)
    finally:
        venv.close()
    for i, sub in enumerate(events):
        _assert_goals_exact(sub, (env_id, i))


def test_expert_is_exact_on_the_batched_envs_numpy_path():
    """12 sub-envs step by the batched env's arrays; the planner rows come from its sub-envs,
    brought up to date when they are read."""
    venv = gym.make_vec("SGCPoint-v1", num_envs=12, vectorization_mode="vector_entry_point")
    try:
        assert venv.unwrapped._batch.fast is not None
        events = _vector_goal_events(venv, SGCExpert(venv), seed=3)
    finally:
        venv.close()
    for i, sub in enumerate(events):
        _assert_goals_exact(sub, i)


def test_expert_is_exact_through_wrappers():
    """Wrappers that leave the observation as it is: Gymnasium's single-env and vector ones."""
    env = gym.wrappers.RecordEpisodeStatistics(
        gym.wrappers.TimeLimit(gym.make("SGCThreeRods-v2"), max_episode_steps=2000)
    )
    record = _run(env, seed=5)
    env.close()
    _assert_exact(record, "SGCThreeRods-v2")
    venv = gym.wrappers.vector.RecordEpisodeStatistics(
        gym.make_vec("SGCRod-v1", num_envs=2, vectorization_mode="vector_entry_point")
    )
    try:
        events = _vector_goal_events(venv, SGCExpert(venv), seed=5)
    finally:
        venv.close()
    for i, sub in enumerate(events):
        _assert_goals_exact(sub, i)


@pytest.mark.parametrize("env_id", ["SGCRod-v1", "SGCRod-v1"])
def test_the_readmes_minimal_example(env_id):
    env = gym.make(env_id)
    expert = SGCExpert(env)
    obs, info = env.reset(seed=0)
    done, goals = False, []
    while not done:
        action, _ = expert.predict(obs)
        obs, reward, terminated, truncated, info = env.step(action)
        done = terminated or truncated
        goals += info.get("goal_reached", [])
    env.close()
    assert not terminated
    _assert_goals_exact(goals, env_id)


def test_on_the_learner_view_the_actions_are_the_planner_versions():
    """Bit for bit, the actions the expert takes on the planner's version of the id."""
    learner = gym.make("SGCThreeRods-v2")
    planner = gym.make("SGCThreeRods-v2", observation="planner")
    mine, theirs = SGCExpert(learner), SGCExpert(planner)
    obs, _ = learner.reset(seed=1)
    reference, _ = planner.reset(seed=1)
    for _ in range(60):
        action, _ = mine.predict(obs)
        assert np.array_equal(action, theirs.predict(reference)[0])
        obs = learner.step(action)[0]
        reference = planner.step(action)[0]
    learner.close()
    planner.close()


def test_on_the_learner_view_a_state_other_than_the_envs_is_refused():
    """The expert acts on its env's current state: an observation that is not the one the env
    last returned raises instead of getting the action for another state."""
    env, other = gym.make("SGCRod-v1"), gym.make("SGCRod-v1")
    expert = SGCExpert(env)
    obs, _ = env.reset(seed=0)
    stranger, _ = other.reset(seed=1)
    first, _ = expert.predict(obs)
    assert np.array_equal(expert.predict(obs[None])[0], first[None])  # a batch of one
    with pytest.raises(ValueError, match="not the one its env last returned"):
        expert.predict(stranger)  # another env's
    env.step(first)
    with pytest.raises(ValueError, match="not the one its env last returned"):
        expert.predict(obs)  # stale: the env has stepped since
    with pytest.raises(ValueError, match="planner's view's size"):
        expert.predict(env.unwrapped.planner_observation())
    with pytest.raises(ValueError, match="observation has shape"):
        expert.predict(np.zeros(5))
    pushed = env.unwrapped.apply_impulse(0, [0.1, 0.0, 0.0])
    assert expert.predict(pushed)[0].shape == env.action_space.shape  # the push's observation
    env.close()
    other.close()
    venv = gym.make_vec("SGCRod-v1", num_envs=2, vectorization_mode="vector_entry_point")
    batch, _ = venv.reset(seed=0)
    expert = SGCExpert(venv)
    with pytest.raises(ValueError, match="not the one its env last returned"):
        expert.predict(batch[::-1])  # the rows of the other sub-env
    with pytest.raises(ValueError, match="observation has shape"):
        expert.predict(batch[0])  # one row of a batch of two
    venv.close()


def test_on_the_planner_view_offline_observations_are_read_as_they_are():
    """The planner's view needs no env state: any observation of it gets its action."""
    env = gym.make("SGCRod-v1", observation="planner")
    expert = SGCExpert(env)
    obs, _ = env.reset(seed=0)
    first, _ = expert.predict(obs)
    env.step(first)
    assert np.array_equal(expert.predict(obs)[0], first)
    env.close()


@pytest.mark.parametrize("env_id", ["SGCPoint-v1", "SGCRod-v1"])
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
    env = gym.make("SGCRod-v1")
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
    env = gym.make("SGCPointGoal-v1")
    obs, _ = env.reset(seed=1)
    action, state = SGCExpert(env).predict(obs)
    assert action.shape == env.action_space.shape and state is None


def test_expert_rejects_a_wrong_observation():
    env = gym.make("SGCPoint-v1", observation="planner")  # read as handed: checked as handed
    with pytest.raises(ValueError, match="observation has shape"):
        SGCExpert(env).predict(np.zeros(5))
    obs, _ = env.reset(seed=0)
    obs[3] = np.nan
    with pytest.raises(ValueError, match="non-finite"):
        SGCExpert(env).predict(obs)


def test_without_the_torque_correction_goals_stay_exact():
    env = gym.make("SGCThreeRods-v2")
    record = run_episode(SGCExpert(env, refine=False), env, seed=7, keep_infos=True)
    env.close()
    _assert_exact(record, "SGCThreeRods-v2")


def test_actions_from_tuples_equal_actions_from_arrays():
    env = gym.make("SGCThreeRods-v2")
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
