"""``sgc convert``: a trusted SB3 statistics pickle becomes the JSON the harness loads (and the
pickle goes), a model zip loses the last rollout's pickled fields, and nothing is unpickled
without ``--trust-model``."""

from __future__ import annotations

import json
import zipfile

import gymnasium as gym
import numpy as np
import pytest

import sgc_env  # noqa: F401  (registers the ids)
from baselines.cli.main import main
from baselines.models.convert import RUNTIME_FIELDS
from baselines.models.normalization import load_statistics


@pytest.fixture
def trained(tmp_path):
    from stable_baselines3 import PPO
    from stable_baselines3.common.env_util import make_vec_env
    from stable_baselines3.common.vec_env import VecNormalize

    venv = VecNormalize(make_vec_env("SGCPoint-v1", n_envs=1, seed=0))
    model = PPO("MlpPolicy", venv, n_steps=64, batch_size=64, seed=0, device="cpu",
                policy_kwargs={"net_arch": [8]})  # fmt: skip
    model.learn(64)
    model.save(tmp_path / "model.zip")
    venv.save(tmp_path / "model.vecnormalize.pkl")
    mean = venv.obs_rms.mean.copy()
    venv.close()
    return tmp_path, mean


def test_nothing_is_unpickled_without_trust(trained, capsys):
    folder, _ = trained
    before = (folder / "model.zip").read_bytes()
    assert main(["convert", str(folder)]) == 2
    assert "--trust-model" in capsys.readouterr().err
    assert (folder / "model.vecnormalize.pkl").is_file()
    assert (folder / "model.zip").read_bytes() == before


def test_a_trusted_folder_converts_to_files_loaded_unpickled(trained, capsys):
    folder, mean = trained
    assert main(["convert", "--trust-model", str(folder)]) == 0
    printed = capsys.readouterr()
    assert "model.vecnormalize.json" in printed.out and "warning" in printed.err
    assert not (folder / "model.vecnormalize.pkl").exists()
    env = gym.make("SGCPoint-v1")
    stats = load_statistics(folder / "model.vecnormalize.json", env)
    np.testing.assert_array_equal(stats.obs_rms.mean, mean)
    with zipfile.ZipFile(folder / "model.zip") as archive:
        data = json.loads(archive.read("data"))
    assert all(data.get(k) is None for k in RUNTIME_FIELDS if k in data)
    assert main(["convert", "--trust-model", str(folder)]) == 0  # again: nothing left to do
    assert "nothing to convert" in capsys.readouterr().out


def test_a_missing_path_is_one_line(tmp_path, capsys):
    assert main(["convert", "--trust-model", str(tmp_path / "missing.pkl")]) == 2
    assert "no such file or folder" in capsys.readouterr().err
