"""The shared evaluation harness: every policy, per-goal rows, scorecard, files, errors."""

from __future__ import annotations

import csv
import json
import math
import subprocess
import sys

import gymnasium as gym
import numpy as np
import pytest

from baselines import MinimumJerkController
from baselines.evaluation.harness import (
    GOAL_COLUMNS,
    SUMMARY_KEYS,
    evaluate,
    write_goals_csv,
    write_summary_json,
)
from baselines.policies import RandomPolicy


def _strict_json(text):
    def reject(name):
        raise ValueError(f"non-standard JSON constant {name}")

    return json.loads(text, parse_constant=reject)


@pytest.mark.parametrize("env_id", ["SGCPoint-v1", "SGCRod-v1"])
@pytest.mark.parametrize("policy", ["expert", "dynamic-constraints", "minimum-jerk", "random"])
def test_every_policy_runs_and_writes_files(policy, env_id, tmp_path):
    result = evaluate(policy, env_id, episodes=1, seed=100)
    assert result.summary["episodes"] == 1 and result.summary["steps"] > 0
    assert set(SUMMARY_KEYS) <= set(result.summary)
    assert result.rows and all(set(GOAL_COLUMNS) <= set(row) for row in result.rows)
    rod = env_id == "SGCRod-v1"
    for row in result.rows:
        assert (row["orientation_error"] is not None) == rod
        assert isinstance(row["success"], bool)
    csv_path = write_goals_csv(result.rows, tmp_path / "goals.csv")
    with csv_path.open() as handle:
        reader = csv.DictReader(handle)
        assert tuple(reader.fieldnames) == GOAL_COLUMNS
        assert len(list(reader)) == len(result.rows)
    summary = _strict_json(write_summary_json(result.summary, tmp_path / "s.json").read_text())
    assert summary["policy"] == policy and summary["env_id"] == env_id
    if policy == "expert":
        assert summary["success_rate"] == 1.0
        assert summary["position_error_max"] <= 1e-8
        if rod:
            assert summary["orientation_error_max"] <= 1e-8


def test_episode_seeds_and_reproducibility():
    a = evaluate("random", "SGCPoint-v1", episodes=2, seed=40)
    b = evaluate("random", "SGCPoint-v1", episodes=2, seed=40)
    assert sorted({row["seed"] for row in a.rows}) == [40, 41]
    assert [r.seed for r in a.episodes] == [40, 41]
    for x, y in zip(a.rows, b.rows, strict=True):
        for key in ("position_error", "closest_approach_offset"):
            assert x[key] == y[key] or (math.isnan(x[key]) and math.isnan(y[key]))
    assert a.episodes[0].infos is not None and a.episodes[1].infos is None


def test_policy_objects_and_factories():
    by_class = evaluate(MinimumJerkController, "SGCPoint-v1", episodes=1, seed=3)
    assert by_class.policy == "MinimumJerkController"
    assert by_class.summary["position_error_max"] <= 1e-6
    space = gym.spaces.Box(-1.0, 1.0, (3,), np.float32)
    by_object = evaluate(RandomPolicy(space, 0), "SGCPoint-v1", 1, 3, label="rand")
    assert by_object.policy == "rand" and by_object.rows[0]["policy"] == "rand"


def test_bad_arguments_name_the_argument(tmp_path):
    with pytest.raises(ValueError, match="env_id"):
        evaluate("expert", "NoSuchEnv-v9", 1, 0)
    with pytest.raises(ValueError, match="episodes"):
        evaluate("expert", "SGCPoint-v1", 0, 0)
    with pytest.raises(ValueError, match="policy"):
        evaluate("nope", "SGCPoint-v1", 1, 0)
    with pytest.raises(ValueError, match="policy"):
        evaluate(str(tmp_path / "missing.zip"), "SGCPoint-v1", 1, 0)
    with pytest.raises(ValueError, match="policy must be"):
        evaluate(42, "SGCPoint-v1", 1, 0)


def test_harness_does_not_import_torch():
    code = "import sys, baselines.evaluation.harness; sys.exit('torch' in sys.modules)"
    assert subprocess.run([sys.executable, "-c", code], check=False).returncode == 0


def test_sb3_model_zip_is_detected_and_evaluated(tmp_path):
    sb3 = pytest.importorskip("stable_baselines3")
    env = gym.make("SGCPoint-v1")
    model = sb3.PPO("MlpPolicy", env, n_steps=16, batch_size=16, device="cpu", seed=0)
    path = tmp_path / "tiny_ppo.zip"
    model.save(path)
    env.close()
    result = evaluate(str(path), "SGCPoint-v1", episodes=1, seed=5)
    assert result.policy == "tiny_ppo"
    assert result.summary["episodes"] == 1 and result.rows
