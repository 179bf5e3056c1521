"""``sgc demos --format minari``: record, load, and replay bit for bit (extra ``minari``)."""

from __future__ import annotations

import warnings
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

minari = pytest.importorskip("minari", reason="the minari extra is not installed")

from baselines.agents.minari_data import fixed_info, record_minari  # noqa: E402
from baselines.cli.main import main  # noqa: E402


@pytest.fixture()
def datasets(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("MINARI_DATASETS_PATH", str(tmp_path))
    return tmp_path


def test_record_load_replay_matches(datasets: Path) -> None:
    publisher = {"author": "sgc tests", "author_email": "tests@sgc.invalid",
                 "code_permalink": "tests/baselines/agents/test_minari_data.py"}  # fmt: skip
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no out-of-space actions, no Minari advice left
        record_minari("SGCRod-v1", 2, 7, "sgc/rod/expert-v0", **publisher)
    dataset = minari.load_dataset("sgc/rod/expert-v0")
    assert dataset.total_episodes == 2
    assert dataset.action_space.dtype == np.float64
    env = dataset.recover_environment()
    for episode in dataset.iterate_episodes():
        assert all(dataset.action_space.contains(a) for a in episode.actions)
        reached = episode.infos["goal_reached"][:, 0]
        assert reached.sum() == 3  # the rod's three goals, each on its own tick
        assert np.nanmax(episode.infos["goal_position_error"]) < 1e-12
        assert np.nanmax(episode.infos["goal_orientation_error"]) < 1e-12
        obs, _ = env.reset(seed=7 + int(episode.id))
        assert obs.tobytes() == episode.observations[0].tobytes()
        for action, recorded in zip(episode.actions, episode.observations[1:], strict=True):
            obs, *_ = env.step(action)
            assert obs.tobytes() == recorded.tobytes()
    env.close()


def test_fixed_info_has_one_shape_on_every_tick() -> None:
    env = gym.make("SGCIntercept-v1")
    _, info = env.reset(seed=0)
    quiet = fixed_info(info, 1)
    event = {"body": 0, "goal": 1, "time": 2.0, "position_error": 1e-16,
             "orientation_error": None}  # fmt: skip
    loud = fixed_info({**info, "goal_reached": [event]}, 1)
    assert quiet.keys() == loud.keys()
    assert not quiet["goal_reached"][0] and loud["goal_reached"][0]
    assert np.isnan(quiet["goal_position_error"][0]) and loud["goal_position_error"][0] == 1e-16
    assert np.isnan(loud["goal_orientation_error"][0])
    env.close()


@pytest.mark.filterwarnings("ignore:`(author|author_email|code_permalink)` is set to None")
def test_cli_writes_a_dataset(datasets: Path, capsys: pytest.CaptureFixture[str]) -> None:
    argv = ["demos", "--env", "SGCIntercept-v1", "--episodes", "1", "--format", "minari",
            "--out", "sgc/intercept/expert-v0"]  # fmt: skip
    assert main(argv) == 0
    assert "1 episodes" in capsys.readouterr().out
    assert minari.load_dataset("sgc/intercept/expert-v0").total_episodes == 1
    assert main([*argv[:-2], "--out", "sgc/intercept/pushed-v0", "--push-scale", "0.1"]) == 2


@pytest.mark.filterwarnings("ignore:`(author|author_email|code_permalink)` is set to None")
def test_an_interrupted_write_leaves_no_dataset(
    datasets: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    real = minari.create_dataset_from_buffers

    def write_then_fail(**kwargs):
        real(**kwargs)  # the files are written (into the staging folder) ...
        raise KeyboardInterrupt  # ... and the process is stopped before the rename

    monkeypatch.setattr(minari, "create_dataset_from_buffers", write_then_fail)
    with pytest.raises(KeyboardInterrupt):
        record_minari("SGCPoint-v1", 1, 0, "sgc/point/cut-v0")
    assert not (datasets / "sgc").exists()
    assert [p.name for p in datasets.iterdir()] == []  # the staging folder went too
    monkeypatch.setattr(minari, "create_dataset_from_buffers", real)
    record_minari("SGCPoint-v1", 1, 0, "sgc/point/cut-v0")
    assert minari.load_dataset("sgc/point/cut-v0").total_episodes == 1
    monkeypatch.setattr(gym, "make", None)  # a taken id is refused before any env is made
    with pytest.raises(ValueError, match="already exists"):
        record_minari("SGCPoint-v1", 1, 0, "sgc/point/cut-v0")


@pytest.mark.parametrize("dataset_id", ["sgc-point", "sgc/point", "../escape-v0", "a b-v0"])
def test_a_malformed_dataset_id_is_refused_before_any_work(
    datasets: Path, capsys: pytest.CaptureFixture[str], dataset_id: str
) -> None:
    with pytest.raises(ValueError, match="dataset_id: expected"):
        record_minari("SGCPoint-v1", 1, 0, dataset_id)
    argv = ["demos", "--env", "SGCPoint-v1", "--episodes", "1", "--format", "minari",
            "--out", dataset_id]  # fmt: skip
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--out: dataset_id: expected" in err[0], err
    assert list(datasets.iterdir()) == []
