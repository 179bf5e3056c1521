"""The smooth rule (expert-smooth): SGC sub-courses between transient sub-goals on the
minimum-jerk reference (baselines/controllers/smooth_table.py, issue 23)."""

from __future__ import annotations

import math

import gymnasium as gym
import numpy as np
import pytest

import sgc_env  # noqa: F401  (registers the ids)
from baselines.controllers.expert import SGCExpert
from baselines.controllers.matched_table import course_key, course_row
from baselines.controllers.smooth_table import LONGEST_SUBCOURSE, smooth_table
from baselines.evaluation.harness import evaluate
from sgc_env.paper import quaternion as quat

GOAL_TOLERANCE = 1e-9


def _scenario(env_id: str, seed: int):
    env = gym.make(env_id)
    env.reset(seed=seed)
    scenario = env.unwrapped.scenario
    env.close()
    return scenario


def test_every_real_goal_is_a_sub_goal_on_the_reference():
    scenario = _scenario("SGCThreeRods-v2", 0)
    table = smooth_table(scenario)
    from sgc_env.envs.tracks import compile_tracks

    for index, tracks in enumerate(compile_tracks(scenario)):
        for name, track in (("position", tracks.position), ("orientation", tracks.orientation)):
            sub = table[(index, name, course_key(course_row(track, 0)))].subgoals
            ticks = np.array(sub.ticks)
            assert np.all(np.diff(ticks) >= 1) and ticks[0] >= 1
            assert np.diff(np.concatenate(([0], ticks))).max() <= LONGEST_SUBCOURSE
            for k in range(track.size):
                if name == "orientation" and track.via[k]:
                    continue  # a somersault's inner piece: the reference need not pass it
                j = sub.ticks.index(int(track.ticks[k]))  # a real goal is a sub-goal
                value, target = sub.values[j], tuple(track.targets[k])
                if name == "position":
                    assert math.dist(value, target) < 1e-12
                else:
                    assert math.hypot(*quat.log(quat.mul_conjugate(value, target))) < 1e-9


def test_expert_smooth_meets_every_goal_within_2x_of_minimum_jerk_on_a_rod():
    """One SGCRod-v1 episode (seconds): goals exact, both kinks within 2x minimum jerk's."""
    smooth = evaluate("expert-smooth", "SGCRod-v1", 1, 10000, keep_infos=0).episodes[0]
    reference = evaluate("minimum-jerk", "SGCRod-v1", 1, 10000, keep_infos=0).episodes[0]
    card, ref = smooth.card["bodies"][0], reference.card["bodies"][0]
    assert card["goals_met"] == card["n_goals"]
    assert card["position_error_max"] < GOAL_TOLERANCE
    assert card["orientation_error_max"] < GOAL_TOLERANCE
    for key in ("acceleration_kink", "angular_acceleration_kink"):
        assert card[key] <= 2.0 * ref[key], key


def test_expert_smooth_needs_its_scenario_and_falls_back_on_another():
    env = gym.make("SGCRod-v1", observation="planner")  # model-only experts read it as handed
    model = SGCExpert(env).model
    with pytest.raises(ValueError, match="needs the env or the episode's scenario"):
        SGCExpert(model=model, end_rule="smooth")
    obs, _ = env.reset(seed=4)
    other = _scenario("SGCRod-v1", 5)  # none of this episode's courses is in its table
    stranger = SGCExpert(model=model, end_rule="smooth", scenario=other)
    tangent = SGCExpert(model=model, end_rule="tangent")
    np.testing.assert_array_equal(stranger.action(obs), tangent.action(obs))
    own = SGCExpert(model=model, end_rule="smooth", scenario=env.unwrapped.scenario)
    assert not np.array_equal(own.action(obs), tangent.action(obs))
    env.close()


def test_expert_smooth_absorbs_a_push():
    """A mid-course impulse becomes a deviation from the sub-goal, re-solved from; every goal
    is still met exactly."""
    from baselines.policies import make_policy

    env = gym.make("SGCRod-v1")
    obs, _ = env.reset(seed=10000)
    policy = make_policy("expert-smooth", env)
    errors, tick, done = [], 0, False
    while not done:
        if tick == 40:
            obs = env.unwrapped.apply_impulse(0, (0.3, 0.0, 0.2))  # the state after the push
        action, _ = policy.predict(obs, episode_start=np.array([tick == 0]))
        obs, _, terminated, truncated, info = env.step(action)
        done, tick = terminated or truncated, tick + 1
        for event in info.get("goal_reached", []):
            errors += [
                e for e in (event["position_error"], event["orientation_error"]) if e is not None
            ]
    env.close()
    assert errors and max(errors) < GOAL_TOLERANCE
