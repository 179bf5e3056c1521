"""PerBodyPolicy on the env's own learner view (LearnerViewBodies): the per-body regrouping,
that it is the one-rod net applied per body, and that a saved model flies the paper's scene
with that scene's gains."""

from __future__ import annotations

from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

pytest.importorskip("stable_baselines3")

import torch as th  # noqa: E402
from stable_baselines3 import PPO  # noqa: E402

from baselines.agents.hyperparams import load_hyperparams, training_class  # noqa: E402
from baselines.agents.smooth_ppo import SmoothPPO  # noqa: E402
from baselines.evaluation.harness import evaluate  # noqa: E402
from baselines.models.model_files import load_sb3_model  # noqa: E402
from baselines.models.per_body import (  # noqa: E402
    LearnerViewBodies,
    PerBodyPolicy,
)
from sgc_env.envs.learner_view import LEARNER_BODY_SIZE, LEARNER_TRACK_SIZE  # noqa: E402
from tests.baselines.models.pd_law import set_pd_law  # noqa: E402

ROOT = Path(__file__).resolve().parents[3]
RANDOM_ID, PAPER_ID, ROD_ID = "SGCThreeRodsRandom-v3", "SGCThreeRods-v2", "SGCRod-v1"
WIDTH = 2 * LEARNER_TRACK_SIZE + 1


def _model(env_id: str, net_arch: list[int] | None = None, **kwargs) -> PPO:
    policy_kwargs = dict(net_arch=[16, 16] if net_arch is None else net_arch, gains_env=env_id,
                         features_extractor_class=LearnerViewBodies, **kwargs)  # fmt: skip
    return PPO(PerBodyPolicy, gym.make(env_id), n_steps=64, batch_size=64, seed=0,
               policy_kwargs=policy_kwargs)  # fmt: skip


def test_the_view_is_regrouped_per_body_without_the_hover() -> None:
    env = gym.make(RANDOM_ID)
    obs, _ = env.reset(seed=2)
    obs, *_ = env.step(env.action_space.sample())
    features = LearnerViewBodies(env.observation_space)(th.as_tensor(obs[None]))[0].numpy()
    assert features.shape == (3 * WIDTH,)
    for b in range(3):
        block = obs[b * LEARNER_BODY_SIZE : (b + 1) * LEARNER_BODY_SIZE]
        np.testing.assert_array_equal(features[b * WIDTH : (b + 1) * WIDTH - 1], block[:-3])
        assert features[(b + 1) * WIDTH - 1] == obs[-1]  # the episode's time fraction


def test_it_is_the_one_rod_net_applied_per_body() -> None:
    three, one = _model(RANDOM_ID, skip=True).policy, _model(ROD_ID, skip=True).policy
    shared = {k: v for k, v in three.state_dict().items()
              if k.startswith(("mlp_extractor.", "action_net.linear.", "log_std"))}  # fmt: skip
    one.load_state_dict(shared, strict=False)
    env = gym.make(RANDOM_ID)
    obs, _ = env.reset(seed=3)
    for _ in range(5):
        obs, *_ = env.step(env.action_space.sample() * 0.1)
    actions, _ = three.predict(obs, deterministic=True)
    for b in range(3):
        block = np.concatenate([obs[b * LEARNER_BODY_SIZE : (b + 1) * LEARNER_BODY_SIZE], obs[-1:]])
        one.action_net.gain.copy_(three.action_net.gain[b : b + 1])
        one.action_net.offset.copy_(three.action_net.offset[b : b + 1])
        action, _ = one.predict(block, deterministic=True)
        np.testing.assert_allclose(action, actions[b * 6 : (b + 1) * 6], rtol=1e-5, atol=1e-6)


def test_a_planner_view_or_a_wrong_size_is_refused_clearly() -> None:
    with pytest.raises(ValueError, match="LearnerViewBodies needs the learner view"):
        policy_kwargs = dict(gains_env=RANDOM_ID, features_extractor_class=LearnerViewBodies)
        PPO(PerBodyPolicy, gym.make(RANDOM_ID, observation="planner"), policy_kwargs=policy_kwargs)
    with pytest.raises(ValueError, match="LearnerViewBodies needs the learner view"):
        LearnerViewBodies(gym.spaces.Box(-1, 1, (10,), np.float32))


def test_a_saved_linear_law_flies_the_paper_scene_with_its_gains(tmp_path: Path) -> None:
    """A hand-set PD law on the view's error and rate (not learned), saved from the random
    family, meets the paper scene's goals when loaded on it (the loader binds that scene's
    gains, half the random family's action per unit of acceleration)."""
    model = _model(RANDOM_ID, net_arch=[])
    assert model.policy.mlp_extractor.width == WIDTH
    set_pd_law(model.policy, 900.0, 60.0)
    path = tmp_path / "linear.zip"
    model.save(path)
    loaded = load_sb3_model(path, env=gym.make(PAPER_ID))
    assert th.allclose(loaded.policy.action_net.gain, 2 * model.policy.action_net.gain)
    bound = evaluate(str(path), PAPER_ID, 1, 0).summary
    assert bound["goals_met"] >= 57 and bound["n_goals"] == 58


@pytest.mark.parametrize("recipe", ["ppo_threerod_learner", "ppo_threerod_smooth"])
def test_the_recipes_name_the_view_and_the_newest_random_id(recipe: str) -> None:
    hp = load_hyperparams("ppo", RANDOM_ID, ROOT / "benchmarks" / "hyperparams" / recipe)
    kwargs = hp.algo_kwargs["policy_kwargs"]
    assert hp.policy is PerBodyPolicy and kwargs["gains_env"] == RANDOM_ID
    assert kwargs["features_extractor_class"] is LearnerViewBodies
    smooth = recipe == "ppo_threerod_smooth"
    assert (training_class(hp) is SmoothPPO) == smooth


def test_the_demo_flies_the_paper_scene_with_any_policy_that_fits(tmp_path: Path) -> None:
    from baselines.figures.demo import DemoOptions, demo_env_id

    learner = tmp_path / "learner.zip"
    _model(RANDOM_ID, net_arch=[]).save(learner)
    assert demo_env_id(DemoOptions(out=tmp_path, policy=str(learner))) == PAPER_ID
    assert demo_env_id(DemoOptions(out=tmp_path, policy="expert")) == "SGCThreeRods-v2"
    rod = tmp_path / "rod.zip"
    PPO("MlpPolicy", gym.make(ROD_ID), n_steps=64, batch_size=64).save(rod)
    with pytest.raises(ValueError, match=r"rod.zip.*does not fit"):
        demo_env_id(DemoOptions(out=tmp_path, policy=str(rod)))
