"""The training-only action-rate term: what it charges, when, and what it refuses."""

from __future__ import annotations

from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

pytest.importorskip("stable_baselines3")

from stable_baselines3.common.vec_env import DummyVecEnv  # noqa: E402

from baselines.agents.action_rate import ActionRatePenalty  # noqa: E402
from baselines.agents.hyperparams import load_hyperparams  # noqa: E402


def _venv(n: int = 2) -> DummyVecEnv:
    return DummyVecEnv([lambda: gym.wrappers.TimeLimit(gym.make("SGCPoint-v1"), 3)] * n)


def _rewards(venv, actions: list[np.ndarray]) -> list[np.ndarray]:
    venv.seed(0)
    venv.reset()
    out = []
    for action in actions:
        _, reward, _, _ = venv.step(action)
        out.append(reward)
    return out


def test_it_charges_the_mean_squared_change_from_the_second_step_of_each_episode() -> None:
    rng = np.random.default_rng(0)
    actions = [rng.uniform(-1.5, 1.5, (2, 3)) for _ in range(5)]  # over the limits: clipped
    plain = _rewards(_venv(), actions)
    charged = _rewards(ActionRatePenalty(_venv(), 4.0), actions)
    clipped = [np.clip(a, -1, 1) for a in actions]
    # steps 1 and 4 start an episode (3 steps each): not charged
    def charge(t: int) -> np.ndarray:
        return 4.0 * np.mean((clipped[t] - clipped[t - 1]) ** 2, axis=1)

    expected = [0.0, charge(1), charge(2), 0.0, charge(4)]
    for t in range(5):
        np.testing.assert_allclose(plain[t] - charged[t], expected[t], rtol=1e-5, atol=1e-6)


def test_a_constant_action_is_never_charged() -> None:
    actions = [np.full((2, 3), 0.3)] * 4
    np.testing.assert_array_equal(_rewards(ActionRatePenalty(_venv(), 9.0), actions),
                                  _rewards(_venv(), actions))  # fmt: skip


@pytest.mark.parametrize("weight", [-1.0, float("nan"), float("inf"), True, "1"])
def test_a_bad_weight_is_refused(weight: object) -> None:
    with pytest.raises(ValueError, match="action_rate: expected a finite weight >= 0"):
        ActionRatePenalty(_venv(), weight)  # type: ignore[arg-type]


def test_a_hyperparameter_file_sets_it_and_a_bad_value_names_the_file(tmp_path: Path) -> None:
    (tmp_path / "ppo.yml").write_text("SGCPoint-v1:\n  n_timesteps: 100\n  policy: MlpPolicy\n"
                                      "  action_rate: 2.5\n")  # fmt: skip
    assert load_hyperparams("ppo", "SGCPoint-v1", tmp_path).action_rate == 2.5
    (tmp_path / "ppo.yml").write_text("SGCPoint-v1:\n  n_timesteps: 100\n  policy: MlpPolicy\n"
                                      "  action_rate: -1\n")  # fmt: skip
    expected = r"ppo.yml: SGCPoint-v1: action_rate: expected a finite weight >= 0, got -1"
    with pytest.raises(ValueError, match=expected):
        load_hyperparams("ppo", "SGCPoint-v1", tmp_path)
