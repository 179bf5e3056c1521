"""The SB3 adapter of the batched env: the same transitions as DummyVecEnv of single envs
(same-step resets, terminal observations, TimeLimit flags, episode statistics), and SB3's
tools (VecNormalize, VecMonitor, evaluate_policy, PPO) plus the expert run on it."""

from __future__ import annotations

import numpy as np
import pytest
from stable_baselines3 import PPO
from stable_baselines3.common.evaluation import evaluate_policy
from stable_baselines3.common.vec_env import VecNormalize

from baselines import SGCExpert
from baselines.agents.sb3_vec_env import BatchedVecEnv, make_sgc_vec
from baselines.common.sub_envs import base_env
from sgc_env.envs.vector import batch as batch_module


@pytest.fixture(autouse=True)
def _numpy_step_from_one_env(monkeypatch: pytest.MonkeyPatch) -> None:
    """Small batches here step by the numpy path, as batches of FAST_MIN_ENVS or more do."""
    monkeypatch.setattr(batch_module, "FAST_MIN_ENVS", 1)


def _equal(a: object, b: object) -> bool:
    if isinstance(a, dict):
        assert isinstance(b, dict)
        return a.keys() == b.keys() and all(np.array_equal(a[k], b[k]) for k in a)
    return bool(np.array_equal(a, b))


@pytest.mark.parametrize("env_id", ["SGCRod-v1", "SGCPointGoal-v1"])
def test_adapter_steps_as_dummy_vec_env(env_id: str) -> None:
    kwargs = {"max_episode_steps": 30}  # truncations come with terminal observations
    batched = make_sgc_vec(env_id, 3, seed=7, vec="batched", env_kwargs=kwargs)
    dummy = make_sgc_vec(env_id, 3, seed=7, vec="dummy", env_kwargs=kwargs)
    rng = np.random.default_rng(0)
    try:
        assert _equal(batched.reset(), dummy.reset())
        ends = 0
        for _ in range(70):
            actions = rng.uniform(-1, 1, (3, *batched.action_space.shape)).astype(np.float32)
            ob, rb, db, ib = batched.step(actions)
            od, rd, dd, idd = dummy.step(actions)
            assert _equal(ob, od) and np.array_equal(rb, rd) and np.array_equal(db, dd)
            for b, d in zip(ib, idd, strict=True):
                assert b.keys() == d.keys()  # the batched env's infos are filled when read
                for key in d.keys() - {"episode", "terminal_observation", "goal_reached"}:
                    assert np.array_equal(b[key], d[key]), key
                assert b.get("goal_reached") == d.get("goal_reached")
                assert b["TimeLimit.truncated"] == d["TimeLimit.truncated"]
                assert ("terminal_observation" in b) == ("terminal_observation" in d)
                if "terminal_observation" in d:
                    ends += 1
                    assert _equal(b["terminal_observation"], d["terminal_observation"])
                    assert b["episode"]["r"] == pytest.approx(d["episode"]["r"], abs=1e-5)
                    assert b["episode"]["l"] == d["episode"]["l"]
        assert ends >= 3
    finally:
        batched.close()
        dummy.close()


def test_ppo_vecnormalize_evaluate_and_expert_on_the_batched_env() -> None:
    """PPO under VecNormalize learns the same parameters on batched and dummy envs."""
    short = {"max_episode_steps": 20}
    params = []
    for kind in ("batched", "dummy"):
        env = VecNormalize(make_sgc_vec("SGCPoint-v1", 4, seed=0, env_kwargs=short, vec=kind))
        model = PPO("MlpPolicy", env, n_steps=16, batch_size=32, n_epochs=1, seed=0)
        model.learn(64)
        assert model.num_timesteps == 64
        params.append(
            np.concatenate([p.detach().numpy().ravel() for p in model.policy.parameters()])
        )
        mean, _ = evaluate_policy(model, env, n_eval_episodes=2, warn=False)
        assert np.isfinite(mean)
        env.close()
    assert np.array_equal(*params)
    returns = []
    for kind in ("batched", "dummy"):
        vec = make_sgc_vec("SGCRod-v1", 2, seed=3, vec=kind)
        expert = SGCExpert(vec)  # reads the masses and limits of sub-env 0
        assert base_env(vec, 1).scenario is vec.get_attr("scenario", [1])[0]
        obs = vec.reset()
        total = np.zeros(2)
        for _ in range(40):
            obs, rewards, _, _ = vec.step(expert.predict(obs)[0])
            total += rewards
        returns.append(total)
        vec.close()
    assert np.array_equal(*returns)


def test_adapter_refuses_bad_input() -> None:
    with pytest.raises(ValueError, match="vec: expected one of"):
        make_sgc_vec("SGCRod-v1", 2, vec="threads")
    with pytest.raises(ValueError, match="no batched env"):
        make_sgc_vec("CartPole-v1", 2, vec="batched")
    env = BatchedVecEnv("SGCRod-v1", 2)
    env.reset()
    actions = np.zeros((2, 6), np.float32)
    actions[1, 3] = np.nan
    with pytest.raises(ValueError, match="sub-env 1: action contains non-finite"):
        env.step(actions)
    with pytest.raises(NotImplementedError, match="does not render"):
        env.get_images()
    env.close()


@pytest.mark.parametrize("policy", ["dc", "mj"])
def test_comparison_policies_run_on_the_batched_env(policy: str) -> None:
    """They read each sub-env's scenario through ``envs`` (baselines.common.sub_envs.sub_env)."""
    from baselines.controllers.comparison_policies import (
        DynamicConstraintsController,
        MinimumJerkController,
    )

    cls = DynamicConstraintsController if policy == "dc" else MinimumJerkController
    runs = []
    for kind in ("batched", "dummy"):
        vec = make_sgc_vec("SGCRod-v1", 2, seed=5, vec=kind)
        controller = cls(vec)
        obs = vec.reset()
        trace = []
        for _ in range(30):
            actions = controller.predict(obs)[0]
            obs, rewards, _, _ = vec.step(actions)
            trace.append((actions, rewards))
        runs.append(trace)
        vec.close()
    for (a, r), (b, s) in zip(*runs, strict=True):
        assert np.array_equal(a, b) and np.array_equal(r, s)
