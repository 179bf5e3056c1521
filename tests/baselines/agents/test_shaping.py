"""The training-only reward shaping (baselines/agents/shaping.py): its offsets are the env's
own schedule cost below the cap, it adds exactly min(x, 1) - x / (1 + x), and a recipe turns it
on."""

from __future__ import annotations

from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

pytest.importorskip("stable_baselines3")

from stable_baselines3.common.vec_env import DummyVecEnv  # noqa: E402

import sgc_env  # noqa: E402, F401
from baselines.agents.hyperparams import load_hyperparams  # noqa: E402
from baselines.agents.shaping import SmoothScheduleCost, schedule_offsets  # noqa: E402
from sgc_env.envs.rewards import schedule_cost, tracks_of  # noqa: E402


def _push(n: int) -> np.ndarray:
    return np.array([0.3 * np.sin(n / 7), 0.0, 0.1, 0.2, -0.1, 0.0], dtype=np.float32)


def test_offsets_are_the_env_schedule_cost_below_the_cap() -> None:
    env = gym.make("SGCRod-v0")
    obs, _ = env.reset(seed=2)
    above = below = 0
    for n in range(120):
        x = schedule_offsets(obs[None])[0, 0]
        costs = [schedule_cost(*track[1:]) for track in tracks_of(env.unwrapped.task)]
        np.testing.assert_allclose(np.minimum(x, 1.0), costs, atol=1e-4)
        above, below = above + int(x.max() > 1.0), below + int(x.min() < 1.0)
        obs, _, terminated, truncated, _ = env.step(_push(n))
        if terminated or truncated:
            break
    assert above > 5 and below > 5  # both sides of the cap were seen
    env.close()


def test_wrapper_adds_the_smooth_minus_capped_cost_and_keeps_the_rest() -> None:
    def make() -> DummyVecEnv:
        venv = DummyVecEnv([lambda: gym.make("SGCRod-v0") for _ in range(2)])
        venv.seed(5)
        return venv

    plain, shaped = make(), SmoothScheduleCost(make())
    plain.reset()
    shaped.reset()
    dones_seen = 0
    for n in range(150):
        action = np.stack([_push(n), -_push(n)])
        obs, r, dones, infos = plain.step(action)
        obs_s, r_s, dones_s, _ = shaped.step(action)
        np.testing.assert_array_equal(obs, obs_s)
        np.testing.assert_array_equal(dones, dones_s)
        after = np.array(obs, dtype=np.float64)
        for i in np.flatnonzero(dones):
            after[i] = infos[i]["terminal_observation"]
        x = schedule_offsets(after)[:, 0, :]
        np.testing.assert_allclose(r_s - r, (np.minimum(x, 1) - x / (1 + x)).sum(1), atol=1e-5)
        assert np.all(r_s >= r - 1e-6)  # x / (1 + x) <= min(x, 1): never below the env's reward
        dones_seen += int(dones.sum())
    assert dones_seen >= 1
    plain.close()
    shaped.close()


def test_alive_turns_the_failure_charge_into_a_per_step_bonus() -> None:
    def make() -> DummyVecEnv:
        venv = DummyVecEnv([lambda: gym.make("SGCRod-v0")])
        venv.seed(3)
        return venv

    plain, alive = make(), SmoothScheduleCost(make(), alive=True)
    plain.reset()
    alive.reset()
    action = np.array([[0.0, 0.0, -0.5, 0.1, 0.0, 0.0]], dtype=np.float32)  # falls out
    worst = 2 + 0.01  # two tracks, one body, plus the effort weight
    for _ in range(200):
        obs, r, dones, infos = plain.step(action)
        _, r_a, _, _ = alive.step(action)
        after = infos[0]["terminal_observation"] if dones[0] else obs[0]
        x = schedule_offsets(np.asarray(after)[None])[0, 0]
        effort = 0.01 * float(np.mean(action**2))
        if dones[0]:
            assert not infos[0]["TimeLimit.truncated"]
            assert r[0] < -100  # the env charged the steps left in one lump
            np.testing.assert_allclose(r_a[0], worst - (x / (1 + x)).sum() - effort, atol=1e-5)
            break
        np.testing.assert_allclose(r_a[0], r[0] + np.minimum(x, 1).sum() - (x / (1 + x)).sum()
                                   + worst, atol=1e-5)  # fmt: skip
    else:
        raise AssertionError("the falling rod never left the workspace")
    plain.close()
    alive.close()


def test_recipe_field_and_bad_values(tmp_path: Path) -> None:
    root = Path(__file__).resolve().parents[3]
    folder = root / "benchmarks" / "archive" / "hyperparams" / "ppo_rod_smooth"
    assert load_hyperparams("ppo", "SGCRod-v0", folder).reward_shaping == "smooth"
    (tmp_path / "ppo.yml").write_text(
        "SGCRod-v0: {n_timesteps: 10, policy: MlpPolicy, reward_shaping: cubic}\n"
    )
    with pytest.raises(ValueError, match="reward_shaping must be"):
        load_hyperparams("ppo", "SGCRod-v0", tmp_path)
    with pytest.raises(ValueError, match="not an SGC layout"):
        schedule_offsets(np.zeros((1, 10)))
