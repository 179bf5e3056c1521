"""scripts/bench_vec_split.py: its timers and its replay of PyBullet's calls measure what they
say (the figures themselves are the script's to print)."""

from __future__ import annotations

import gymnasium as gym
import pytest

import sgc_env  # noqa: F401
from sgc_env.envs.sgc_env import SGCEnv
from tests.script_module import load_script


@pytest.fixture(scope="module")
def split():
    return load_script("bench_vec_split")


def test_timers_count_resets_and_draws_then_restore(split):
    original = SGCEnv.__dict__["reset"]
    env = gym.make("SGCThreeRodsRandom-v3")
    with split.Timers("SGCThreeRodsRandom-v3") as timers:
        assert SGCEnv.__dict__["reset"] is not original
        env.reset(seed=0)
    env.close()
    assert SGCEnv.__dict__["reset"] is original
    assert timers.spent["reset"] >= timers.spent["draw"] > 0.0


def test_tick_split_and_physics_floor_on_a_small_batch(split):
    ms, env = split.tick_split("SGCRod-v1", 12, "batched", 4)
    try:
        assert ms["total"] >= ms["reset"] >= ms["draw"] >= 0.0
        assert ms["total"] > 0.0
        floor, bodies, worlds = split.physics_floor(env.get_attr("unwrapped"), 2)
    finally:
        env.close()
    assert floor > 0.0 and bodies == 12 and 1 <= worlds <= 12
