"""What the registry declares: episode lengths for TimeLimit and TimeAwareObservation, and
made envs that the ecosystem's checkers accept as they come out of ``gym.make``."""

from __future__ import annotations

import warnings
from dataclasses import replace

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.wrappers import TimeAwareObservation
from stable_baselines3.common.env_checker import check_env as sb3_check_env

import sgc_env
from baselines import SGCExpert
from sgc_env.envs import SGCEnv
from sgc_env.episode_steps import random_steps_bound, scenario_steps
from sgc_env.scenes import PRESETS, random_scenario


@pytest.mark.parametrize("env_id", sgc_env.ENV_IDS)
def test_every_id_declares_its_episode_length(env_id: str) -> None:
    bound = gym.spec(env_id).max_episode_steps
    env = gym.make(env_id)
    own = env.unwrapped.max_steps
    env.close()
    assert bound is not None
    if "random_scenario" in gym.spec(env_id).kwargs:
        assert bound >= own
    else:
        assert bound == own  # the TimeLimit and the env truncate on the same step


DRAWS = {"point": 300, "rod": 300, "intercept": 100, "three_rods": 2}  # three rods: planned


@pytest.mark.parametrize("preset", sorted(PRESETS))
def test_random_bound_covers_every_draw(preset: str) -> None:
    bound = random_steps_bound(preset)
    rng = np.random.default_rng(0)
    steps = [scenario_steps(random_scenario(rng, preset)) for _ in range(DRAWS[preset])]
    assert max(steps) <= bound


def test_random_bound_is_reached_by_the_slowest_draws() -> None:
    """With the ranges pinned to their worst case every draw is as long as the bound allows
    (within a tick per course): the bound follows the generator, not a guess."""
    worst = replace(PRESETS["point"], spacing=(0.8, 0.8), speed=(0.5, 0.5), n_goals=(3, 3))
    bound = random_steps_bound(worst)
    rng = np.random.default_rng(1)
    steps = [scenario_steps(random_scenario(rng, worst)) for _ in range(20)]
    assert bound - 3 <= min(steps) and max(steps) <= bound


@pytest.mark.parametrize("env_id", ["SGCRod-v1", "SGCIntercept-v1"])
def test_time_aware_observation_runs_to_the_env_own_truncation(env_id: str) -> None:
    env = TimeAwareObservation(gym.make(env_id))
    expert = SGCExpert(env.env)  # flies the env's own observation, without the appended steps
    obs, _ = env.reset(seed=3)
    steps, truncated, terminated = 0, False, False
    while not (truncated or terminated):
        assert obs[-1] == steps  # the elapsed steps TimeAwareObservation appends
        action, _ = expert.predict(obs[:-1])
        obs, _, terminated, truncated, _ = env.step(action)
        steps += 1
    assert truncated and not terminated
    assert steps == env.unwrapped.max_steps  # neither early nor late
    assert env.observation_space.contains(obs)
    env.close()


@pytest.mark.parametrize("env_id", sgc_env.ENV_IDS)
def test_sb3_checker_passes_on_the_made_env(env_id: str) -> None:
    """As made, wrappers included; SB3's checker calls a goal env's ``compute_reward`` on the
    env it is given, which Gymnasium's wrappers do not forward, so the goal id is checked
    unwrapped (SB3's HER reaches it through ``get_wrapper_attr``, as tested here)."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        env = gym.make(env_id)
        if env_id == "SGCPointGoal-v1":
            assert callable(env.get_wrapper_attr("compute_reward"))
            sb3_check_env(env.unwrapped)
        else:
            sb3_check_env(env)
        env.close()


def test_a_longer_episode_than_the_registered_limit_is_refused() -> None:
    """A scenario the registry's TimeLimit would cut short is an error, not a silent cut."""
    kwargs = {"scenario": "point_three_goals", "control_frequency": 240}
    env = gym.make("SGCPoint-v1", **kwargs)
    with pytest.raises(ValueError, match="lasts 420 steps .* after 306; pass max_episode_steps"):
        env.reset(seed=0)
    env.close()
    # The caller's own limit (or none) is respected where the env can see it: gym.make's
    # TimeLimit is invisible to the env (no wrapper may check it: make_vec refuses ids with
    # additional wrappers), so a longer episode is made directly or through make_vec.
    direct = SGCEnv(**kwargs)
    direct.reset(seed=0)
    direct.close()
    for steps in (-1, 420, 100):
        vec = gym.make_vec(
            "SGCPoint-v1", 2, "vector_entry_point", max_episode_steps=steps, **kwargs
        )
        vec.reset(seed=0)
        vec.close()
    vec = gym.make_vec("SGCPoint-v1", 2, "vector_entry_point", **kwargs)
    with pytest.raises(ValueError, match="lasts 420 steps .* after 306; pass max_episode_steps"):
        vec.reset(seed=0)
    vec.close()


EARLIER = {"SGCPoint-v0": "SGCPoint-v1", "SGCRod-v0": "SGCRod-v1",
           "SGCThreeRods-v1": "SGCThreeRods-v2", "SGCIntercept-v0": "SGCIntercept-v1",
           "SGCInterceptRandom-v0": "SGCInterceptRandom-v1", "SGCPointGoal-v0": "SGCPointGoal-v1",
           "SGCThreeRodsRandom-v2": "SGCThreeRodsRandom-v3"}  # fmt: skip
"""The versions before 1.0 and their current ids (CHANGELOG.md, "Migrating to 1.0")."""


def test_one_version_per_task() -> None:
    registered = [k for k in gym.registry if k.startswith("SGC")]
    assert sorted(registered) == sorted(sgc_env.ENV_IDS) == sorted(EARLIER.values())


@pytest.mark.parametrize("old", sorted(EARLIER))
def test_an_earlier_version_is_gymnasiums_deprecated_env_naming_the_current(old: str) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)  # Gymnasium's own line before it
        with pytest.raises(gym.error.DeprecatedEnv, match=f"Please use `{EARLIER[old]}`"):
            gym.make(old)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the package's check says it once, without the line
        with pytest.raises(ValueError, match=f"^--env: .*{old[-2:]} for `.*` is deprecated.*"
                                             f"{EARLIER[old]}"):  # fmt: skip
            sgc_env.check_env_id(old, "--env")
