"""The harness on the batched env: the same episodes as one single env, N at a time."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest

from baselines.evaluation.episodes import run_episodes_batched, sub_info
from baselines.evaluation.harness import evaluate, json_ready
from baselines.policies import make_policy
from sgc_env.envs.vector.vector_env import make_vec


def _as_json(value):
    """Equal JSON means equal values, NaN included (NaN != NaN in a plain comparison)."""
    return json.dumps(json_ready(value), sort_keys=True)


def _infos(infos):
    """Infos without "TimeLimit.truncated": rl_zoo3's gym_patches (imported by other tests)
    make Gymnasium's TimeLimit add it on a single env's last step; the batched env has no
    TimeLimit wrapper (as in tests/sgc_env/envs/test_batch.py)."""
    return [{k: v for k, v in info.items() if k != "TimeLimit.truncated"} for info in infos]


def _without_wall_time(summary):
    return {k: v for k, v in summary.items() if k != "wall_time_s"}


@pytest.mark.parametrize(
    ("env_id", "policy", "episodes", "num_envs"),
    [
        ("SGCRod-v1", "expert", 5, 3),  # more episodes than sub-envs: sub-envs are reused
        ("SGCIntercept-v1", "minimum-jerk", 3, 2),  # per-sub-env state in the policy
        ("SGCInterceptRandom-v1", "dynamic-constraints", 3, 3),  # a scene drawn per reset
        ("SGCPoint-v1", "expert", 4, 4),
    ],
)
def test_batched_episodes_equal_single_env_episodes(env_id, policy, episodes, num_envs):
    single = evaluate(policy, env_id, episodes, seed=20000, keep_infos=episodes)
    batched = evaluate(policy, env_id, episodes, seed=20000, keep_infos=episodes, num_envs=num_envs)
    assert _as_json(batched.rows) == _as_json(single.rows)
    assert _as_json(_without_wall_time(batched.summary)) == _as_json(
        _without_wall_time(single.summary)
    )
    for a, b in zip(single.episodes, batched.episodes, strict=True):
        assert (a.episode, a.seed, a.steps, a.episode_return) == (
            b.episode, b.seed, b.steps, b.episode_return
        )  # fmt: skip
        assert _as_json(_infos(a.infos)) == _as_json(_infos(b.infos))
        assert _as_json(a.initial_info) == _as_json(b.initial_info)
    assert batched.summary["wall_time_s"] > 0


def test_batched_episodes_cut_at_max_steps_like_single_episodes():
    env = make_vec("SGCRod-v1", 2)
    try:
        policy = make_policy("expert", env)
        records = run_episodes_batched(policy, env, [1, 2, 3], max_steps=7)
    finally:
        env.close()
    assert [r.steps for r in records] == [7, 7, 7]
    assert [r.seed for r in records] == [1, 2, 3]


def test_random_policy_acts_in_one_sub_envs_action_space():
    result = evaluate("random", "SGCRod-v1", 3, seed=5, num_envs=3)
    assert result.summary["episodes"] == 3 and result.summary["steps"] > 0


def test_sub_info_reads_masked_keys():
    infos = {"a": np.array([1.0, 2.0]), "_a": np.array([True, False]), "b": np.array([3, 4])}
    assert sub_info(infos, 0) == {"a": 1.0, "b": 3}
    assert sub_info(infos, 1) == {"b": 4}


@pytest.mark.parametrize("bad", [0, -1, 1.5, True])
def test_num_envs_is_checked(bad):
    with pytest.raises(ValueError, match="num_envs"):
        evaluate("expert", "SGCPoint-v1", 2, seed=0, num_envs=bad)


def test_more_sub_envs_than_episodes_is_refused_by_the_runner():
    env = make_vec("SGCPoint-v1", 3)
    try:
        with pytest.raises(ValueError, match="at most one sub-env per episode"):
            run_episodes_batched(make_policy("expert", env), env, [0, 1])
    finally:
        env.close()


def test_cli_num_envs(tmp_path):
    out = subprocess.run(
        [sys.executable, "-m", "baselines.cli.main", "evaluate", "--env", "SGCPoint-v1",
         "--episodes", "3", "--num-envs", "2", "--no-plots", "--out", str(tmp_path / "e")],
        capture_output=True, text=True, check=False,
    )  # fmt: skip
    assert out.returncode == 0, out.stderr
    summary = json.loads((tmp_path / "e" / "summary.json").read_text())
    assert summary["episodes"] == 3 and summary["goals_met"] == summary["n_goals"]
    bad = subprocess.run(
        [sys.executable, "-m", "baselines.cli.main", "evaluate", "--num-envs", "0"],
        capture_output=True, text=True, check=False,
    )  # fmt: skip
    assert bad.returncode == 2 and "--num-envs" in bad.stderr
