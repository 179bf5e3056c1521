"""Demonstrations, behaviour cloning and DAgger on the newest ids: the expert acts on the
planner's view of the state, the learner's observation is what is stored and trained on."""

from __future__ import annotations

from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

pytest.importorskip("stable_baselines3")

from baselines.agents.demos import load_demos, record_demos  # noqa: E402
from baselines.agents.train import TrainConfig, train  # noqa: E402
from baselines.policies import make_policy  # noqa: E402
from sgc_env.envs.learner_view import learner_size  # noqa: E402

TINY_PPO = """
SGCPoint-v1:
  n_timesteps: 128
  policy: MlpPolicy
  normalize: "dict(norm_obs=False, norm_reward=True, gamma=0.98)"
  n_envs: 2
  n_steps: 64
  batch_size: 64
  n_epochs: 1
  policy_kwargs: "dict(net_arch=[32])"
"""


def test_demos_store_the_learners_observation_and_the_experts_planner_action(
    tmp_path: Path,
) -> None:
    """Same actions and rewards, bit for bit, as demos of the planner's version; the stored
    observations are what the learner's env returned before each action."""
    demos = record_demos("SGCPoint-v1", 2, seed=3)
    planner = record_demos("SGCPoint-v1", 2, seed=3, env_kwargs={"observation": "planner"})
    assert demos.observations.shape[1] == learner_size(1)
    assert np.array_equal(demos.actions, planner.actions)
    assert np.array_equal(demos.rewards, planner.rewards)
    env = gym.make("SGCPoint-v1")
    starts = np.flatnonzero(demos.episode_starts)
    obs, _ = env.reset(seed=3)
    for k in range(starts[1]):  # the first episode, replayed
        assert np.array_equal(obs, demos.observations[k]), k
        obs = env.step(demos.actions[k])[0]
    env.close()
    loaded = load_demos(demos.save(tmp_path / "demos.npz"))
    assert loaded.env_id == "SGCPoint-v1"
    assert np.array_equal(loaded.observations, demos.observations)


def test_dagger_labels_the_learners_states_with_the_expert_on_their_planner_view() -> None:
    """Every appended row: the learner's observation of a state the clone visited and the
    expert's action on the planner's view of that same state (a replay of the round on the
    learner's and the planner's versions side by side gives both, bit for bit)."""
    from stable_baselines3 import PPO

    from baselines.agents.bc import dagger

    demos = record_demos("SGCPoint-v1", 1, seed=0)
    env = gym.make("SGCPoint-v1")
    model = PPO("MlpPolicy", env, policy_kwargs={"net_arch": [16]}, seed=0, device="cpu")
    learner, planner = gym.make("SGCPoint-v1"), gym.make("SGCPoint-v1", observation="planner")
    expert = make_policy("expert", planner)
    rollout_seed = 0 + 1_000_000  # dagger's first rollout seed (see its docstring)
    obs, _ = learner.reset(seed=rollout_seed)
    theirs, _ = planner.reset(seed=rollout_seed)
    states, labels = [], []
    done = False
    while not done:
        states.append(obs)
        labels.append(np.clip(expert.predict(theirs)[0], -1.0, 1.0))
        action, _ = model.predict(obs, deterministic=True)
        obs, _, terminated, truncated, _ = learner.step(action)
        theirs = planner.step(action)[0]
        done = terminated or truncated
    aggregate, result = dagger(model, demos, rounds=1, episodes_per_round=1, seed=0, epochs=1)
    added = slice(len(demos), None)
    assert result.rounds[0]["samples"] == len(demos) + len(states)
    assert np.array_equal(aggregate.observations[added], np.asarray(states, np.float32))
    assert np.array_equal(aggregate.actions[added], np.asarray(labels, np.float32))
    assert np.abs(aggregate.actions[added]).max() > 0.0
    for made in (env, learner, planner):
        made.close()


def test_behaviour_cloning_trains_on_the_learners_view(tmp_path: Path) -> None:
    """`sgc train --init bc` on a learner's id: demos recorded there fit the model's
    observation space, cloning lowers the imitation loss, DAgger adds the clone's states."""
    folder = tmp_path / "hp"
    folder.mkdir()
    (folder / "ppo.yml").write_text(TINY_PPO)
    path = record_demos("SGCPoint-v1", 2, seed=0).save(tmp_path / "demos.npz")
    result = train(
        TrainConfig(
            algo="ppo", env_id="SGCPoint-v1", seed=0, timesteps=0, init="bc", demos=path,
            bc_epochs=15, dagger_rounds=1, dagger_episodes=1, hyperparams_dir=folder,
        )  # fmt: skip
    )
    assert result.model.observation_space.shape == (learner_size(1),)
    assert result.bc is not None
    assert result.bc["loss_after"] < 0.5 * result.bc["loss_before"]
    assert result.bc["samples_after_dagger"] > result.bc["samples"]
    assert result.model.get_env().gamma == 0.98  # rl-zoo3's normalize: gamma, as written


def test_normalize_gamma_out_of_range_names_the_field(tmp_path: Path) -> None:
    from baselines.agents.hyperparams import load_hyperparams

    (tmp_path / "ppo.yml").write_text(TINY_PPO.replace("gamma=0.98", "gamma=1.5"))
    with pytest.raises(ValueError, match="SGCPoint-v1: normalize: gamma must be in"):
        load_hyperparams("ppo", "SGCPoint-v1", tmp_path)
