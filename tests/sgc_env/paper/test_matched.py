"""The matched end rule: end velocities solved over a track, the quartic rest, the expert."""

from __future__ import annotations

import math

import gymnasium as gym
import numpy as np
import pytest

import sgc_env  # noqa: F401  (registers the ids)
from baselines.controllers.expert import SGCExpert, substep_lag
from baselines.controllers.matched_table import course_key, matched_table
from baselines.evaluation.harness import evaluate
from sgc_env.paper.frames import course_end_velocity, solve_course_in_frame
from sgc_env.paper.hermite import RestQuarticProfile
from sgc_env.paper.matched import matched_end_velocities

GOAL_TOLERANCE = 1e-9


def test_rest_quartic_arrives_at_rest_without_acceleration_and_is_time_consistent():
    p = RestQuarticProfile(0.7, -2.0, 0.5)
    assert p.state(0.0)[:2] == pytest.approx((0.7, -2.0))
    assert p.state(0.5) == pytest.approx((0.0, 0.0, 0.0), abs=1e-12)
    d, v, _ = p.state(0.2)
    again = RestQuarticProfile(d, v, 0.3)
    for t in (0.0, 0.1, 0.25):
        assert again.state(t) == pytest.approx(p.state(0.2 + t), abs=1e-12)
    t = np.linspace(0.0, 0.5, 7)
    np.testing.assert_allclose(np.array(p.evaluate(t)).T, [p.state(x) for x in t], atol=1e-12)


def _track() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A wiggly position track: starts ``D_i(0) = nail_{i-1} - nail_i``, durations."""
    rng = np.random.default_rng(3)
    nails = np.cumsum(rng.normal(size=(7, 3)) * 0.3 + np.array([1.0, 0.3, 0.0]), axis=0)
    prev = np.vstack((np.zeros(3), nails[:-1]))
    return prev - nails, rng.uniform(0.4, 0.9, 7), nails


def _chain(starts, durations, v0, ends):
    courses, rate = [], v0
    for i in range(len(durations)):
        last = i == len(durations) - 1
        _, info = course_end_velocity(
            starts[i], None if last else starts[i + 1], durations[i],
            None if last else durations[i + 1], end_velocity=ends[i] if last else None,
            rule="tangent",
        )  # fmt: skip
        courses.append(solve_course_in_frame(info.frame, starts[i], rate, durations[i], ends[i]))
        rate = ends[i]
    return courses


def test_matched_velocities_make_the_acceleration_continuous_at_every_goal():
    starts, durations, _ = _track()
    v0, end = np.array([0.5, 0.0, 0.0]), np.array([1.0, 0.2, 0.0])
    solved = matched_end_velocities(starts, durations, v0, end, orientation=False)
    assert solved.converged and solved.mismatch_before > 1.0  # the tangent rule jumps
    np.testing.assert_allclose(solved.velocities[-1], end, atol=1e-12)
    courses = _chain(starts, durations, v0, solved.velocities)
    for c, n in zip(courses[:-1], courses[1:], strict=True):
        d_end, _, a_end = c.state(c.duration)
        np.testing.assert_allclose(d_end, 0.0, atol=GOAL_TOLERANCE)  # still exact
        np.testing.assert_allclose(a_end, n.state(0.0)[2], atol=1e-6)
    # the tangent rule's velocities (the solver's start) do jump
    tangent = matched_end_velocities(starts[:1], durations[:1], v0, end, orientation=False)
    assert tangent.free == ()


def test_matched_keeps_rest_before_a_dwell_and_checks_its_input():
    starts, durations, _ = _track()
    starts = np.vstack((starts[:3], np.zeros((1, 3)), starts[3:]))  # goal 3 repeats goal 2
    durations = np.concatenate((durations[:3], [0.3], durations[3:]))
    solved = matched_end_velocities(starts, durations, np.zeros(3), np.zeros(3), orientation=False)
    assert 2 not in solved.free and 3 not in solved.free
    np.testing.assert_array_equal(solved.velocities[2], 0.0)  # arrives at rest, then dwells
    with pytest.raises(ValueError, match="one per course"):
        matched_end_velocities(starts, durations[:-1], np.zeros(3), np.zeros(3), orientation=False)


def test_substep_lag_is_the_held_force_velocity_lag():
    # 4 substeps: the velocity after the period is behind the plan's by H D'' / 5
    assert substep_lag(1 / 60, 4) == pytest.approx(2 / 60 / 5)
    assert substep_lag(0.1, 1) == pytest.approx(0.1)  # one step: the chord, lag H


def test_expert_matched_meets_every_goal_and_needs_its_scenario():
    env = gym.make("SGCRod-v1")
    with pytest.raises(ValueError, match="end_rule must be one of"):
        SGCExpert(env, end_rule="spline")
    with pytest.raises(ValueError, match="needs the env or the episode's scenario"):
        SGCExpert(model=SGCExpert(env).model, end_rule="matched")
    env.reset(seed=3)
    table = matched_table(env.unwrapped.scenario)
    track = env.unwrapped.task.tracks[0].position
    assert course_key([*track.course_start[0], track.durations[0], *track.next_start[0],
                       track.next_duration[0]]) in table  # fmt: skip
    env.close()
    result = evaluate("expert-matched", "SGCRod-v1", 2, 3, keep_infos=0)
    for record in result.episodes:
        card = record.card["bodies"][0]
        assert card["goals_met"] == card["n_goals"]
        assert card["position_error_max"] < GOAL_TOLERANCE
        assert card["orientation_error_max"] < GOAL_TOLERANCE
        assert math.isfinite(card["acceleration_kink"])


def test_episode_expert_reads_each_sub_envs_scenario():
    """In a vector env every sub-env draws its own scenario: each sub-env's expert looks its
    courses up in its own table, so no course falls back to the tangent rule."""
    from baselines.policies import make_policy

    envs = gym.vector.SyncVectorEnv([lambda: gym.make("SGCRod-v1") for _ in range(2)])
    obs, _ = envs.reset(seed=[5, 6])
    policy = make_policy("expert-matched", envs)
    policy.predict(obs, episode_start=np.array([True, True]))
    for i, sub in enumerate(envs.envs):
        expert = policy._experts[i]
        track = sub.unwrapped.task.tracks[0].position
        key = [*track.course_start[0], track.durations[0], *track.next_start[0],
               track.next_duration[0]]  # fmt: skip
        assert expert._scenario is sub.unwrapped.scenario
        assert expert._matched(tuple(np.float32(key).tolist()) + (0.0,) * 5) is not None
    envs.close()
