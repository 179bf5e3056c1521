"""SmoothPPO (CAPS terms after each PPO update): the pairs it smooths are consecutive states of
one episode, zero weights are PPO step for step, the terms make the policy smoother, bad
weights are refused, and the hyperparameter files choose it."""

from __future__ import annotations

from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

pytest.importorskip("stable_baselines3")

import torch as th  # noqa: E402
from stable_baselines3 import PPO  # noqa: E402
from stable_baselines3.common.vec_env import DummyVecEnv  # noqa: E402

from baselines.agents.hyperparams import load_hyperparams, training_class  # noqa: E402
from baselines.agents.smooth_ppo import SmoothPPO  # noqa: E402


class Counter(gym.Env):
    """Observes (its own index, the step in the episode, noise); episodes of 3 steps; the
    reward pays for actions that follow the noise (so PPO has something to learn)."""

    def __init__(self, index: int) -> None:
        self.index = index
        self.observation_space = gym.spaces.Box(-10, 10, (3,), np.float32)
        self.action_space = gym.spaces.Box(-1, 1, (2,), np.float32)

    def _obs(self) -> np.ndarray:
        return np.array([self.index, self.t, self.np_random.normal()], dtype=np.float32)

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        super().reset(seed=seed)
        self.t = 0
        self.last = self._obs()
        return self.last, {}

    def step(self, action):
        reward = -float(np.sum((action - self.last[2]) ** 2))
        self.t += 1
        self.last = self._obs()
        return self.last, reward, False, self.t >= 3, {}


def _venv() -> DummyVecEnv:
    venv = DummyVecEnv([lambda i=i: Counter(i) for i in range(4)])
    venv.seed(0)
    return venv


def _model(cls: type = SmoothPPO, **kwargs) -> PPO:
    return cls("MlpPolicy", _venv(), n_steps=16, batch_size=32, n_epochs=2, seed=0, **kwargs)


def test_each_state_gets_its_successor_in_the_same_episode() -> None:
    model = _model(temporal=1.0).learn(64)
    seen = 0
    for data in model.rollout_buffer.get(32):
        buffer = model.rollout_buffer
        now, after = data.observations.numpy(), buffer.successors.numpy()
        has = buffer.has_successor.numpy().astype(bool)
        np.testing.assert_array_equal(now[has, 0], after[has, 0])  # the same sub-env
        np.testing.assert_array_equal(after[has, 1], now[has, 1] + 1)  # its next step
        seen += int(has.sum())
    # every within-episode pair of the rollout: 4 envs x 16 steps, episodes of 3 steps
    assert seen == int((model.rollout_buffer.episode_starts[1:] == 0).sum()) > 20


def test_zero_weights_are_ppo_step_for_step() -> None:
    smooth = _model().learn(128)  # each built and trained in turn: they share torch's RNG
    plain = _model(PPO).learn(128)
    for a, b in zip(smooth.policy.parameters(), plain.policy.parameters(), strict=True):
        assert th.equal(a, b)


def _roughness(model: PPO, obs: th.Tensor) -> float:
    """Mean change of the mean action from one state of the rollout to the next."""
    with th.no_grad():
        mean = model.policy.get_distribution(obs).distribution.mean
    return float((mean[1:] - mean[:-1]).norm(dim=-1).mean())


def test_the_terms_make_consecutive_actions_closer() -> None:
    rough = _model(PPO).learn(1024)
    smooth = _model(temporal=20.0, spatial=20.0).learn(1024)
    obs = th.as_tensor(rough.rollout_buffer.observations[:16])  # one sub-env's steps
    assert _roughness(smooth, obs) < 0.5 * _roughness(rough, obs)


@pytest.mark.parametrize(
    ("field", "value"),
    [("temporal", -1.0), ("spatial", float("nan")), ("spatial_std", float("inf")),
     ("temporal", True)],
)  # fmt: skip
def test_bad_settings_are_refused_by_name(field: str, value: object) -> None:
    with pytest.raises(ValueError, match=f"^{field}: expected"):
        _model(**{field: value})


def test_a_file_with_smoothness_fields_trains_with_smooth_ppo(tmp_path: Path) -> None:
    (tmp_path / "ppo.yml").write_text(
        "SGCPoint-v1:\n  n_timesteps: 100\n  policy: MlpPolicy\n  n_steps: 64\n  temporal: 2.0\n"
        "SGCRod-v1:\n  n_timesteps: 100\n  policy: MlpPolicy\n"
    )
    assert training_class(load_hyperparams("ppo", "SGCPoint-v1", tmp_path)) is SmoothPPO
    assert training_class(load_hyperparams("ppo", "SGCRod-v1", tmp_path)) is PPO
    (tmp_path / "ppo.yml").write_text("SGCPoint-v1:\n  n_timesteps: 100\n  policy: MlpPolicy\n"
                                      "  smooth: 2.0\n")  # fmt: skip
    with pytest.raises(ValueError, match="unknown field 'smooth' for PPO"):
        load_hyperparams("ppo", "SGCPoint-v1", tmp_path)
