"""The learner features (ScheduleFeatures): what they compute, that they carry enough to meet
goals, and that a model trained on them evaluates from its file alone."""

from __future__ import annotations

import json
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

pytest.importorskip("stable_baselines3")

import torch as th  # noqa: E402

import sgc_env  # noqa: E402, F401
from baselines.agents.hyperparams import load_hyperparams  # noqa: E402
from baselines.agents.train import TrainConfig, train  # noqa: E402
from baselines.models.schedule_features import TRACK_FEATURES, ScheduleFeatures  # noqa: E402
from sgc_env.envs.rewards import TRACK_COST_CAP, schedule_cost, tracks_of  # noqa: E402

BENCHMARK_HP = Path(__file__).resolve().parents[3] / "benchmarks" / "hyperparams"


def _features(extractor: ScheduleFeatures, obs: np.ndarray) -> np.ndarray:
    with th.no_grad():
        return extractor(th.as_tensor(obs[None])).numpy()[0]


def _by_hand(env: gym.Env, obs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """D - D_sched and D' - D'_sched of the point, as docs/environments.md defines them."""
    layout = env.unwrapped.layout

    def get(name: str) -> np.ndarray:
        return obs[layout.body_slice(0, name)].astype(np.float64)

    t_left, duration = get("position_time_left")[0], get("position_course_duration")[0]
    start, end_velocity = get("position_course_start"), get("position_end_velocity")
    if t_left >= 0 and duration > 0:
        schedule, rate = start * t_left / duration, -start / duration
    else:
        schedule, rate = -end_velocity * t_left, end_velocity
    return get("position_deviation") - schedule, get("point_velocity") - rate


def test_features_are_the_on_schedule_error_and_its_rate() -> None:
    env = gym.make("SGCPoint-v0")
    extractor = ScheduleFeatures(env.observation_space)
    assert extractor.features_dim == 2 * TRACK_FEATURES + 1
    obs, _ = env.reset(seed=3)
    rng = np.random.default_rng(0)
    done, after_last, against_reward = False, 0, 0
    while not done:  # a noisy hover-and-follow, so both branches (in a course, after it) occur
        feats = _features(extractor, obs)
        error, rate = _by_hand(env, obs)
        np.testing.assert_allclose(feats[0:3] * 0.05, error, atol=1e-5)
        np.testing.assert_allclose(feats[3:6] * 0.5, rate, atol=1e-5)
        (_, d, left, course, floor), = tracks_of(env.unwrapped.task)  # the reward's own schedule
        cost = schedule_cost(d, left, course, floor)
        if cost < TRACK_COST_CAP:
            scale = max(float(np.linalg.norm(course[:3])), floor)
            assert np.linalg.norm(feats[0:3] * 0.05) == pytest.approx(cost * scale, abs=1e-5)
            against_reward += 1
        assert np.all(feats[TRACK_FEATURES : 2 * TRACK_FEATURES - 2] == 0)  # no orientation track
        assert feats[-1] == pytest.approx(0.0981)
        after_last += int(feats[TRACK_FEATURES - 3] < 0)  # time left < 0: after the last goal
        action = -0.05 * feats[0:3] - 0.1 * feats[3:6] + [0, 0, feats[-1]] + rng.normal(0, 0.05, 3)
        obs, _, terminated, truncated, _ = env.step(action.astype(np.float32))
        done = terminated or truncated
    assert not terminated and after_last > 5 and against_reward > 100
    env.close()


def test_a_linear_policy_on_the_features_meets_every_goal() -> None:
    """A fixed PD law on the features (100 s^-2, 20 s^-1) meets every goal within 2 cm on its
    tick: what a learner has to find is close to linear in them."""
    env = gym.make("SGCPoint-v0")
    extractor = ScheduleFeatures(env.observation_space)
    errors = []
    for seed in range(3):
        obs, _ = env.reset(seed=20_000 + seed)
        done = False
        while not done:
            f = _features(extractor, obs).astype(np.float64)
            acceleration = -100.0 * f[0:3] * 0.05 - 20.0 * f[3:6] * 0.5
            action = acceleration / 100.0 + np.array([0.0, 0.0, f[-1]])
            obs, _, terminated, truncated, info = env.step(action.astype(np.float32))
            errors += [e["position_error"] for e in info.get("goal_reached", [])]
            done = terminated or truncated
    assert len(errors) == 9
    assert max(errors) < 0.02
    env.close()


def test_orientation_track_and_several_bodies() -> None:
    env = gym.make("SGCRod-v0")
    extractor = ScheduleFeatures(env.observation_space)
    obs, _ = env.reset(seed=0)
    feats = _features(extractor, obs)
    assert feats[2 * TRACK_FEATURES - 2] == 1.0  # the rod has an orientation track
    env.close()
    three = gym.make("SGCThreeRods-v1")
    assert ScheduleFeatures(three.observation_space).features_dim == 3 * (2 * TRACK_FEATURES + 1)
    with pytest.raises(ValueError, match="gravity: expected 3 values"):
        ScheduleFeatures(three.observation_space, gravity=[0.1, 0.1])
    three.close()


def test_rejects_observations_that_are_not_an_sgc_layout() -> None:
    with pytest.raises(ValueError, match="not an SGC layout"):
        ScheduleFeatures(gym.spaces.Box(-1, 1, (10,), np.float32))
    with pytest.raises(ValueError, match="flat Box"):
        ScheduleFeatures(gym.spaces.Box(-1, 1, (2, 5), np.float32))  # type: ignore[arg-type]


def test_benchmark_recipe_resolves_the_features_and_reward_only_normalisation() -> None:
    hp = load_hyperparams("ppo", "SGCPoint-v0", BENCHMARK_HP / "ppo_schedule")
    assert hp.normalize and hp.normalize_kwargs == {"norm_obs": False, "norm_reward": True}
    assert hp.algo_kwargs["policy_kwargs"]["features_extractor_class"] is ScheduleFeatures


@pytest.mark.parametrize(
    ("value", "match"),
    [("'dict(norm_obs=False, norm_obz=True)'", "unknown keys"), ("3", "true/false or a mapping")],
)
def test_normalize_field_errors_name_it(tmp_path: Path, value: str, match: str) -> None:
    (tmp_path / "ppo.yml").write_text(
        f"SGCPoint-v0: {{n_timesteps: 64, policy: MlpPolicy, normalize: {value}}}\n"
    )
    with pytest.raises(ValueError, match=match):
        load_hyperparams("ppo", "SGCPoint-v0", tmp_path)


def test_model_on_the_features_evaluates_from_its_file_alone(tmp_path: Path) -> None:
    from baselines.evaluation.harness import evaluate
    from baselines.policies import load_sb3_model

    (tmp_path / "ppo.yml").write_text(
        "SGCPoint-v0: {n_timesteps: 128, policy: MlpPolicy, n_steps: 64, batch_size: 64,\n"
        "  n_epochs: 1, normalize: 'dict(norm_obs=False, norm_reward=True)',\n"
        "  policy_kwargs: 'dict(net_arch=[8], features_extractor_class=ScheduleFeatures)'}\n"
    )
    out = tmp_path / "run"
    train(TrainConfig(algo="ppo", env_id="SGCPoint-v0", hyperparams_dir=tmp_path, out=out))
    assert json.loads((out / "vecnormalize.json").read_text())["norm_obs"] is False
    model = load_sb3_model(out / "final_model.zip", env=gym.make("SGCPoint-v0"))
    assert isinstance(model.policy.features_extractor, ScheduleFeatures)
    config = json.loads((out / "config.json").read_text())
    assert "ScheduleFeatures" in config["hyperparams"]["policy_kwargs"]
    result = evaluate(str(out / "final_model.zip"), "SGCPoint-v0", 1, 20_000)
    assert result.summary["n_goals"] >= 1


@pytest.mark.slow
def test_ppo_on_the_features_learns_point_goals_from_scratch(tmp_path: Path) -> None:
    """The `ppo-schedule` benchmark recipe, no demonstrations (about 5 min on one core)."""
    result = train(
        TrainConfig(
            algo="ppo", env_id="SGCPoint-v0", seed=0, timesteps=300_000,
            hyperparams_dir=BENCHMARK_HP / "ppo_schedule", eval_freq=300_000, eval_episodes=20,
            eval_seed=20_000,
        )  # fmt: skip
    )
    assert result.evaluations[-1]["success_rate"] >= 0.5


def test_squash_bounds_the_error_and_its_rate_and_keeps_the_rest() -> None:
    env = gym.make("SGCRod-v0")
    plain = ScheduleFeatures(env.observation_space)
    squashed = ScheduleFeatures(env.observation_space, squash=3.0)
    obs, _ = env.reset(seed=1)
    for _ in range(40):  # full thrust up and spin: the body runs far off its schedule
        obs, *_ = env.step(np.array([0, 0, 1, 1, 0, 0], dtype=np.float32))
    raw, out = _features(plain, obs), _features(squashed, obs)
    n = TRACK_FEATURES
    errors = np.r_[0:6, n : n + 6]  # error and rate of both tracks
    assert np.abs(raw[errors]).max() > 10  # far off: the unsquashed inputs are large
    np.testing.assert_allclose(out[errors], 3.0 * np.tanh(raw[errors] / 3.0), rtol=1e-5, atol=1e-6)
    assert np.abs(out[errors]).max() <= 3.0
    rest = np.setdiff1d(np.arange(raw.size), errors)
    np.testing.assert_array_equal(out[rest], raw[rest])
    for bad in (0.0, -1.0, "3"):
        with pytest.raises(ValueError, match="squash"):
            ScheduleFeatures(env.observation_space, squash=bad)  # type: ignore[arg-type]
    env.close()
