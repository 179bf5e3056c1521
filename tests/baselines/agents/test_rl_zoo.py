"""rl-zoo3, unmodified, trains on our ids from the packaged hyperparameter files."""

from __future__ import annotations

import json
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
        sys.executable, "-m", "rl_zoo3.train", "--algo", "ppo", "--env", "SGCPoint-v1",
        "--gym-packages", "sgc_env", "--conf-file", str(hyperparams_file("ppo")),
        "-n", "256", "--hyperparams", "n_envs:1", "n_steps:128", "batch_size:64",
        "--eval-freq", "-1", "--save-freq", "-1", "--vec-env", "dummy", "--seed", "0",
        "--device", "cpu", "-f", str(tmp_path / "logs"),
    ]  # fmt: skip
    done = subprocess.run(command, capture_output=True, text=True, timeout=600, cwd=tmp_path)
    assert done.returncode == 0, done.stderr[-3000:]
    assert "total_timesteps      | 256" in done.stdout
    (model_file,) = (tmp_path / "logs" / "ppo").glob("SGCPoint-v1_*/SGCPoint-v1.zip")
    from stable_baselines3 import PPO

    env = gym.make("SGCPoint-v1")
    model = PPO.load(model_file, device="cpu")
    obs, _ = env.reset(seed=0)
    action, _ = model.predict(obs, deterministic=True)
    assert env.action_space.contains(action)
    env.close()


ZOO = Path(__file__).resolve().parents[3] / "benchmarks" / "zoo"


@pytest.mark.parametrize("algo", ["ppo", "sac", "td3", "her"])
def test_zoo_files_name_stock_classes_and_the_newest_ids(algo: str) -> None:
    """``benchmarks/zoo/*.yml``: keyed by the newest ids, SB3's own policies, no project class
    or wrapper (what a researcher runs with the field's tools)."""
    from rl_zoo3.utils import get_wrapper_class

    import sgc_env

    text = (ZOO / f"{algo}.yml").read_text()
    import yaml

    table = yaml.safe_load(text)
    assert table and set(table) <= set(sgc_env.ENV_IDS)
    for env_id, hp in table.items():
        assert hp["policy"] in ("MlpPolicy", "MultiInputPolicy"), env_id
        assert get_wrapper_class(hp) is None and "env_wrapper" not in hp
        assert "baselines" not in str(hp) and "Features" not in str(hp)


def test_rl_zoo3_model_on_the_newest_rod_scores_through_the_harness(tmp_path: Path) -> None:
    """rl-zoo3 trains PPO on ``SGCRod-v1`` from ``benchmarks/zoo/ppo.yml`` (a few steps); its
    pickled statistics are refused until converted, then the harness scores the model."""
    command = [
        sys.executable, "-m", "rl_zoo3.train", "--algo", "ppo", "--env", "SGCRod-v1",
        "--gym-packages", "sgc_env", "--conf-file", str(ZOO / "ppo.yml"),
        "-n", "256", "--hyperparams", "n_envs:2", "n_steps:64", "batch_size:64",
        "--eval-freq", "-1", "--save-freq", "-1", "--seed", "0", "--device", "cpu",
        "-f", str(tmp_path / "logs"),
    ]  # fmt: skip
    done = subprocess.run(command, capture_output=True, text=True, timeout=600, cwd=tmp_path)
    assert done.returncode == 0, done.stderr[-3000:]
    (model_file,) = (tmp_path / "logs" / "ppo").glob("SGCRod-v1_*/SGCRod-v1.zip")
    stats = model_file.parent / "SGCRod-v1" / "vecnormalize.pkl"
    assert stats.is_file()
    from baselines.evaluation.harness import evaluate

    with pytest.raises(ValueError, match="pickle.*convert"):
        evaluate(str(model_file), "SGCRod-v1", episodes=1, seed=20000)
    from baselines.cli.main import main

    assert main(["convert", str(stats)]) == 2  # it unpickles: only when trusted
    assert stats.is_file()
    assert main(["convert", "--trust-model", str(stats)]) == 0
    assert stats.with_suffix(".json").is_file() and not stats.exists()
    result = evaluate(str(model_file), "SGCRod-v1", episodes=1, seed=20000)
    assert result.summary["episodes"] == 1
    table = subprocess.run(
        [sys.executable, "scripts/zoo_seed_table.py", str(model_file.parent), "--episodes", "1",
         "--json", str(tmp_path / "rows.json")],
        capture_output=True, text=True, timeout=300, cwd=Path(__file__).resolve().parents[3],
    )  # fmt: skip
    assert table.returncode == 0, table.stderr[-2000:]
    (row,) = json.loads((tmp_path / "rows.json").read_text())
    assert (row["env_id"], row["seed"], row["steps"]) == ("SGCRod-v1", 0, 256)
    assert row["n_goals"] == result.summary["n_goals"] and row["training_s"] > 0
    met = int(row["success_rate"] >= 0.8)
    assert f"{met}/1 runs meet >= 80% of held-out goals" in table.stdout
