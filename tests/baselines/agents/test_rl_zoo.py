"""rl-zoo3, unmodified, trains on our ids from the packaged hyperparameter files."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import gymnasium as gym
import pytest

pytest.importorskip("rl_zoo3", reason="rl_zoo3 is in the dev extra")

from baselines.common.shipped import hyperparams_file  # noqa: E402


def test_rl_zoo3_trains_ppo_on_sgc_point(tmp_path: Path) -> None:
    """A few hundred steps with ``python -m rl_zoo3.train`` (smaller rollouts than the file's,
    overridden on the command line as a zoo user would); the saved model acts on the env."""
    command = [
        sys.executable, "-m", "rl_zoo3.train", "--algo", "ppo", "--env", "SGCPoint-v0",
        "--gym-packages", "sgc_env", "--conf-file", str(hyperparams_file("ppo")),
        "-n", "256", "--hyperparams", "n_envs:1", "n_steps:128", "batch_size:64",
        "--eval-freq", "-1", "--save-freq", "-1", "--vec-env", "dummy", "--seed", "0",
        "--device", "cpu", "-f", str(tmp_path / "logs"),
    ]  # fmt: skip
    done = subprocess.run(command, capture_output=True, text=True, timeout=600, cwd=tmp_path)
    assert done.returncode == 0, done.stderr[-3000:]
    assert "total_timesteps      | 256" in done.stdout
    (model_file,) = (tmp_path / "logs" / "ppo").glob("SGCPoint-v0_*/SGCPoint-v0.zip")
    from stable_baselines3 import PPO

    env = gym.make("SGCPoint-v0")
    model = PPO.load(model_file, device="cpu")
    obs, _ = env.reset(seed=0)
    action, _ = model.predict(obs, deterministic=True)
    assert env.action_space.contains(action)
    env.close()
