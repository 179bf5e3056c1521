"""The comparison policies, the policy factory and the episode-fresh expert on the env."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import sgc_env  # noqa: F401  (registers the env ids)
from baselines import DynamicConstraintsController, MinimumJerkController, SGCExpert
from baselines.evaluation.harness import run_episode
from baselines.policies import (
    BUILTIN_POLICIES,
    EpisodeExpert,
    NormalizedPolicy,
    RandomPolicy,
    algorithm_from_data,
    make_policy,
    policy_labels,
    vecnormalize_path,
)
from sgc_env.envs.sgc_env import SGCEnv
from sgc_env.metrics import goals_from_scenario, score_episode


def _rollout(env, policy, seed):
    obs, first = env.reset(seed=seed)
    infos, done, start = [], False, True
    while not done:
        action, _ = policy.predict(obs, episode_start=np.array([start]))
        start = False
        obs, _, term, trunc, info = env.step(action)
        infos.append(info)
        done = term or trunc
    goals = goals_from_scenario(env.unwrapped.scenario)
    card = score_episode(infos, goals, env.unwrapped.dt, initial_info=first)
    return infos, first, goals, card


def test_exports_are_the_classes():
    from baselines.controllers.comparison_policies import DynamicConstraintsController as dc
    from baselines.controllers.expert import SGCExpert as expert

    assert DynamicConstraintsController is dc and SGCExpert is expert
    assert MinimumJerkController.__module__ == "baselines.controllers.comparison_policies"


@pytest.mark.parametrize("env_id", ["SGCPoint-v1", "SGCRod-v1"])
def test_episode_expert_exact_on_redrawn_scenarios(env_id):
    """Seed 3 redraws force limits: the plain expert's construction-time model goes stale."""
    env = gym.make(env_id)
    policy = make_policy("expert", env)
    assert isinstance(policy, EpisodeExpert)
    for seed in (3, 4):
        _, _, _, card = _rollout(env, policy, seed)
        assert card["position_error_max"] <= 1e-8
        if env_id == "SGCRod-v1":
            assert card["orientation_error_max"] <= 1e-8
    env.close()


@pytest.mark.parametrize("env_id", ["SGCPoint-v1", "SGCRod-v1"])
def test_minimum_jerk_meets_goals_with_continuous_velocity(env_id):
    env = gym.make(env_id)
    policy = MinimumJerkController(env)
    for seed in (0, 5):
        infos, _, goals, card = _rollout(env, policy, seed)
        assert card["position_error_max"] <= 1e-6
        if env_id == "SGCRod-v1":
            assert card["orientation_error_max"] <= 1e-6
        assert card["success_rate"] == 1.0
        # Velocity continuity: the step across a goal changes the velocity no more than
        # ordinary steps do (with discrete samples a smooth motion shows |a| dt everywhere).
        v = np.array([i["point_velocity"][0] for i in infos])
        steps = np.linalg.norm(np.diff(v, axis=0), axis=1)
        jumps = [row["velocity_jump"] for row in card["bodies"][0]["position_goals"][:-1]]
        assert max(jumps) <= 1.5 * np.percentile(steps, 95) + 1e-9
    env.close()


def test_minimum_jerk_one_spline_per_sub_env():
    envs = gym.vector.SyncVectorEnv([lambda: gym.make("SGCPoint-v1")] * 2)
    policy = MinimumJerkController(envs)
    obs, _ = envs.reset(seed=[11, 12])
    errors = []
    starts = np.ones(2, dtype=bool)
    for _ in range(400):
        action, _ = policy.predict(obs, episode_start=starts)
        starts[:] = False
        obs, _, term, trunc, info = envs.step(action)
        if "goal_reached" in info:
            for events, mask in zip(info["goal_reached"], info["_goal_reached"], strict=True):
                if mask:
                    errors += [e["position_error"] for e in events]
        if np.any(term | trunc):
            break
    envs.close()
    assert len(errors) >= 4
    assert max(errors) <= 1e-6


@pytest.mark.parametrize(("source", "seed"), [("point_three_goals", 0), ("SGCPoint-v1", 2)])
def test_dynamic_constraints_shows_figure1_pathology(source, seed):
    """Figure 1: goals met early or late with the body nearly stopped, never at t_i."""
    env = gym.make(source) if source.startswith("SGC") else SGCEnv(scenario=source)
    policy = DynamicConstraintsController(env, eps=1e-3)
    _, first, goals, card = _rollout(env, policy, seed)
    dt = env.unwrapped.dt
    interior = len(goals[0]) - 1
    events = [e for e in policy.meet_events() if e.track == "position"]
    assert len(events) >= interior
    previous, t_prev = np.asarray(first["point_position"][0]), 0.0
    for goal, event in zip(goals[0][:interior], events, strict=False):
        average = np.linalg.norm(np.asarray(goal.nail) - previous) / (goal.time - t_prev)
        assert event.speed < 0.05 * average
        assert abs(event.time - goal.time) >= dt - 1e-9
        previous, t_prev = np.asarray(goal.nail), goal.time
    rows = card["bodies"][0]["position_goals"]
    assert all(row["position_error"] > 1e-3 for row in rows[:interior])
    assert card["speed_minima_total"] >= interior
    env.close()


def test_dynamic_constraints_rejects_bad_eps():
    env = gym.make("SGCPoint-v1")
    with pytest.raises(ValueError, match="eps"):
        DynamicConstraintsController(env, eps=0.0)
    env.close()


def test_random_policy_is_seeded_and_inside_the_space():
    space = gym.spaces.Box(-1.0, 1.0, (6,), np.float32)
    a = [RandomPolicy(space, 7).predict(np.zeros(3))[0] for _ in range(2)]
    np.testing.assert_array_equal(a[0], a[1])
    batch, _ = RandomPolicy(space, 7).predict(np.zeros((4, 3)))
    assert batch.shape == (4, 6) and space.contains(batch[0])


def test_make_policy_errors(tmp_path):
    env = gym.make("SGCPoint-v1")
    with pytest.raises(ValueError, match="policy: unknown spec 'nope'"):
        make_policy("nope", env)
    with pytest.raises(ValueError, match="does not exist"):
        make_policy(str(tmp_path / "missing.zip"), env)
    env.close()
    goal_env = gym.make("SGCPointGoal-v1")
    assert isinstance(make_policy("random", goal_env, seed=0), RandomPolicy)
    goal_env.close()


@pytest.mark.parametrize("env_id", ["SGCPointGoal-v1", "SGCPointGoal-v1"])
@pytest.mark.parametrize("spec", ["expert", "minimum-jerk", "dynamic-constraints"])
def test_the_planner_policies_read_a_goal_envs_dict(env_id, spec):
    """Through the ``observation`` entry (the planner's view) or the env's planner view (the
    learner's): the expert and minimum jerk meet every goal exactly, dynamic constraints as on
    the flat id."""
    env = gym.make(env_id)
    record = run_episode(make_policy(spec, env), env, seed=3)
    flat = gym.make("SGCPoint-v1")
    expected = run_episode(make_policy(spec, flat), flat, seed=3)
    assert record.card["success_rate"] == expected.card["success_rate"]
    assert record.card["position_error_max"] == expected.card["position_error_max"]
    if spec != "dynamic-constraints":
        assert record.card["position_error_max"] <= 1e-9


def test_policy_labels_are_distinct():
    assert policy_labels(["expert", "a/m.zip", "b/m.zip", "c/x/n.zip", "d/x/n.zip"]) == [
        "expert", "a-m", "b-m", "c-x-n", "d-x-n",
    ]  # fmt: skip
    assert policy_labels(["random", "runs/model.zip"]) == ["random", "model"]
    with pytest.raises(ValueError, match="'expert' is given more than once"):
        policy_labels(["expert", "random", "expert"])
    with pytest.raises(ValueError, match="given more than once"):
        policy_labels(["a/m.zip", "./a/m.zip"])  # one file, two spellings
    with pytest.raises(ValueError, match="distinct labels"):
        policy_labels(["/x/a-m.zip", "/x/a/m.zip", "/y/a/m.zip"])


@pytest.mark.parametrize(
    ("model", "stats"),
    [
        ("final_model.zip", "vecnormalize.json"),
        ("ppo_2048_steps.zip", "ppo_vecnormalize_2048_steps.json"),
    ],
)
def test_models_trained_behind_vecnormalize_get_their_statistics(tmp_path, model, stats):
    from stable_baselines3 import PPO
    from stable_baselines3.common.vec_env import DummyVecEnv, VecNormalize

    from baselines.models.normalization import save_statistics

    env = gym.make("SGCPoint-v1")
    ppo = PPO("MlpPolicy", env, n_steps=64, batch_size=64, seed=0, device="cpu")
    ppo.save(tmp_path / model)
    plain = make_policy(str(tmp_path / model), env)
    assert vecnormalize_path(tmp_path / model) is None and not isinstance(plain, NormalizedPolicy)
    normalizer = VecNormalize(DummyVecEnv([lambda: gym.make("SGCPoint-v1")]), norm_reward=False)
    normalizer.obs_rms.mean[:] = 3.0
    normalizer.obs_rms.var[:] = 4.0
    save_statistics(normalizer, tmp_path / stats)
    policy = make_policy(str(tmp_path / model), env)
    assert vecnormalize_path(tmp_path / model) == tmp_path / stats
    assert isinstance(policy, NormalizedPolicy) and not policy.vec_normalize.training
    obs, _ = env.reset(seed=0)
    expected, _ = ppo.predict(
        np.clip((obs - 3.0) / np.sqrt(4.0 + 1e-8), -10, 10), deterministic=True
    )
    np.testing.assert_allclose(policy.predict(obs)[0], expected, rtol=1e-6, atol=1e-6)
    assert not np.allclose(policy.predict(obs)[0], plain.predict(obs)[0])
    env.close()


def _policy_class(module):
    return type("Policy", (), {"__module__": module})


@pytest.mark.parametrize(
    ("module", "extra", "expected"),
    [
        ("stable_baselines3.sac.policies", {}, "SAC"),
        ("stable_baselines3.td3.policies", {"policy_delay": 2, "target_noise_clip": 0.5}, "TD3"),
        ("stable_baselines3.td3.policies", {"policy_delay": 1, "target_noise_clip": 0.0}, "DDPG"),
        ("stable_baselines3.common.policies", {"clip_range": 0.2}, "PPO"),
        ("stable_baselines3.common.policies", {"normalize_advantage": False}, "A2C"),
    ],
)
def test_algorithm_from_data(module, extra, expected):
    assert algorithm_from_data({"policy_class": _policy_class(module), **extra}) == expected


def test_algorithm_from_data_rejects_foreign_data():
    with pytest.raises(ValueError, match="policy_class"):
        algorithm_from_data({})
    with pytest.raises(ValueError, match="cannot tell"):
        algorithm_from_data({"policy_class": _policy_class("my.policies")})


def test_every_policy_kind_satisfies_the_policy_protocol():
    """Runtime: isinstance on the Protocol; static shape: predict takes SB3's parameters by
    name with SB3's defaults, and returns (action, state) with the action in the space."""
    import inspect

    from stable_baselines3 import PPO

    from baselines.policies import Policy

    env = gym.make("SGCPoint-v1")
    obs, _ = env.reset(seed=0)
    policies = {spec: make_policy(spec, env, seed=0) for spec in BUILTIN_POLICIES}
    policies["SGCExpert"] = SGCExpert(env)
    policies["PPO"] = PPO("MlpPolicy", env, n_steps=64, batch_size=64, seed=0, device="cpu")
    for name, policy in policies.items():
        assert isinstance(policy, Policy), name
        params = inspect.signature(policy.predict).parameters
        assert list(params)[:4] == ["observation", "state", "episode_start", "deterministic"]
        assert params["state"].default is None and params["episode_start"].default is None
        assert isinstance(params["deterministic"].default, bool), name  # SB3's is False
        action, _ = policy.predict(
            obs, state=None, episode_start=np.array([True]), deterministic=True
        )
        assert env.action_space.contains(np.asarray(action, np.float32)), name
    assert not isinstance(object(), Policy)
    env.close()
