"""The shared per-body policy (PerBodyPolicy): shapes, that it is the single-body net applied
per body, the env-bound action gains, and that a saved model evaluates from its file alone on
a scene with other limits."""

from __future__ import annotations

import zipfile
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

pytest.importorskip("stable_baselines3")

import torch as th  # noqa: E402
from stable_baselines3 import PPO  # noqa: E402

import sgc_env  # noqa: E402
from baselines.evaluation.harness import evaluate  # noqa: E402
from baselines.models.model_files import load_sb3_model  # noqa: E402
from baselines.models.per_body import (  # noqa: E402
    BODY_ACTIONS,
    REFERENCE_ACCELERATION,
    PerBodyPolicy,
    body_gains,
)
from tests.baselines.models.pd_law import set_pd_law  # noqa: E402

RANDOM_ID = next(i for i in sgc_env.ENV_IDS if i.startswith("SGCThreeRodsRandom-"))
PAPER_ID = "SGCThreeRods-v2"
SHARED = ("mlp_extractor.", "action_net.linear.", "value_net.linear.", "log_std")


def _model(env_id: str, net_arch: list[int] | None = None, **kwargs) -> PPO:
    env = gym.make(env_id)
    policy_kwargs = dict(net_arch=[16, 16] if net_arch is None else net_arch, gains_env=env_id,
                         **kwargs)  # fmt: skip
    return PPO(PerBodyPolicy, env, n_steps=64, batch_size=64, seed=0, policy_kwargs=policy_kwargs)


def test_shapes_and_one_log_std_per_action_component() -> None:
    model = _model(RANDOM_ID)
    policy = model.policy
    obs = np.stack([model.env.observation_space.sample() * 0 for _ in range(4)])
    obs_t = th.as_tensor(obs)
    actions, values, log_prob = policy(obs_t)
    assert actions.shape == (4, 3 * BODY_ACTIONS)
    assert values.shape == (4, 1) and log_prob.shape == (4,)
    assert policy.predict_values(obs_t).shape == (4, 1)
    assert policy.log_std.shape == (BODY_ACTIONS,)
    # the noise is in acceleration units: the action's std is exp(log_std) * gain
    std = policy.get_distribution(obs_t).distribution.stddev[0].detach().numpy()
    gain, _ = body_gains(gym.make(RANDOM_ID))
    assert np.allclose(std, np.exp(policy.log_std_init) * gain.ravel(), rtol=1e-5)


def test_gains_follow_the_limits_the_agent_does_not_observe() -> None:
    rod_gain, rod_offset = body_gains(gym.make("SGCRod-v1"))
    assert np.allclose(rod_gain, 1.0, rtol=0.02)  # the reference is SGCRod-v1's own scale
    assert rod_offset[0, 2] == pytest.approx(9.81 / 100.0) and not rod_offset[0, 3:].any()
    paper, _ = body_gains(gym.make(PAPER_ID))
    drawn, _ = body_gains(gym.make(RANDOM_ID))
    assert np.allclose(paper, 2 * drawn)  # the random family has twice the paper's limits
    env = gym.make(PAPER_ID).unwrapped
    env.reset(seed=0)
    limit = env.scenario.bodies[0].force_limit
    assert paper[0, 0] == pytest.approx(REFERENCE_ACCELERATION * 1.0 / limit)
    with pytest.raises(ValueError, match="built for 1 bodies, the env has 3"):
        _model("SGCRod-v1").policy.bind_env(gym.make(PAPER_ID))
    with pytest.raises(ValueError, match="6 actions per body"):
        body_gains(gym.make("SGCPoint-v1"))


def test_a_model_whose_gains_env_was_renamed_since_rebinds_to_the_env(tmp_path: Path) -> None:
    """An id renamed since training: a warning, and the file's own gains, re-bound to the env
    it is loaded on (the paper scene's, twice the random family's)."""
    model = _model(RANDOM_ID, net_arch=[])
    set_pd_law(model.policy, 900.0, 60.0)
    path = tmp_path / "linear.zip"
    model.save(path)
    loaded = load_sb3_model(path, env=gym.make(PAPER_ID))
    assert th.allclose(loaded.policy.action_net.gain, 2 * model.policy.action_net.gain)
    with zipfile.ZipFile(path) as archive:
        members = {name: archive.read(name) for name in archive.namelist()}
    members["data"] = members["data"].replace(RANDOM_ID.encode(), b"SGCRenamed-v9")
    renamed = tmp_path / "renamed.zip"
    with zipfile.ZipFile(renamed, "w") as archive:
        for name, blob in members.items():
            archive.writestr(name, blob)
    with pytest.warns(UserWarning, match="'SGCRenamed-v9' is not registered"):
        again = load_sb3_model(renamed, env=gym.make(PAPER_ID))
    assert th.equal(again.policy.action_net.gain, loaded.policy.action_net.gain)


def test_the_features_are_the_learner_view_per_body() -> None:
    from baselines.models.features import StandardizeObservation

    with pytest.raises(ValueError, match="features_extractor_class must be LearnerViewBodies"):
        _model(RANDOM_ID, features_extractor_class=StandardizeObservation)


def test_the_shipped_model_flies_the_paper_scene() -> None:
    """>= 90 % of the paper scene's 58 goals for the model trained without demonstrations on
    the random family (docs/zoo.md); one episode: the scene is fixed and the policy
    deterministic."""
    from baselines.zoo.manifest import CHECKPOINTS, load_manifest

    name = "ppo_caps_SGCThreeRodsRandom-v3.zip"
    entry = next(e for e in load_manifest(CHECKPOINTS) if e["file"] == name)
    assert entry["demonstrations"] is False and entry["timesteps"] > 0
    summary = evaluate(str(CHECKPOINTS / name), PAPER_ID, 1, 20_000).summary
    assert summary["n_goals"] == 58 and summary["goals_met"] >= 0.9 * 58, summary
    assert summary["terminated"] == 0
