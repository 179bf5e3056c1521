"""The tangent end-velocity rule beyond the paper, its fallbacks, and where it is chosen."""

from __future__ import annotations

import math

import gymnasium as gym
import numpy as np
import pytest

import sgc_env
from baselines.controllers.expert import SGCExpert
from baselines.evaluation.harness import evaluate
from baselines.policies import EpisodeExpert, make_policy
from sgc_env.paper.frames import K_MIN, PACE_STEP, course_end_velocity, tangent_speed
from sgc_env.paper.plan import BodyState, PlanOptions, PositionGoal, plan_body
from sgc_env.scenario import load_scenario, scenario_from_dict

GOAL_TOLERANCE = 1e-9


def _turn(deg: float, length: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """``D_i(0)`` of a unit course along +x and the next course turned by ``deg`` in xy."""
    a = math.radians(deg)
    d = np.array([-1.0, 0.0, 0.0])  # previous nail at -x of the nail: moving along +x
    nxt = -length * np.array([math.cos(a), math.sin(a), 0.0])
    return d, nxt


@pytest.mark.parametrize("deg", [0.0, 20.0, 60.0, 80.0])
def test_tangent_velocity_follows_the_chord_through_the_neighbours(deg):
    d, nxt = _turn(deg)
    v, info = course_end_velocity(d, nxt, 1.0, 1.0, rule="tangent")
    assert info.rule == "tangent"
    chord = -(d + nxt)  # nail_{i+1} - nail_{i-1}
    np.testing.assert_allclose(v / np.linalg.norm(v), chord / np.linalg.norm(chord), atol=1e-12)
    assert np.linalg.norm(v) == pytest.approx(1.0)  # both courses average 1 m/s
    assert np.all(info.k >= K_MIN)
    # realised per component of S_i: v_j = -k_j D_j(0) / t_i
    np.testing.assert_allclose(info.frame @ v, -info.k * (info.frame @ d), atol=1e-12)
    # the paper's assumption is reported, not required
    assert info.within_paper_assumption == (deg <= 30.0)


def test_paper_rule_is_unchanged_and_differs():
    d, nxt = _turn(20.0, length=2.0)
    v_default, _ = course_end_velocity(d, nxt, 1.0, 1.0)
    v_paper, info = course_end_velocity(d, nxt, 1.0, 1.0, rule="paper")
    np.testing.assert_array_equal(v_default, v_paper)
    assert info.rule == "sgc"
    v_tangent, _ = course_end_velocity(d, nxt, 1.0, 1.0, rule="tangent")
    assert np.linalg.norm(v_tangent - v_paper) > 0.05


@pytest.mark.parametrize("deg", [130.0, 180.0])
def test_tangent_falls_back_to_the_paper_where_it_cannot_be_realised(deg):
    """130 degrees: the chord leaves the cone of S_i (a sign change); 180: a hairpin."""
    d, nxt = _turn(deg)
    v, info = course_end_velocity(d, nxt, 1.0, 1.0, rule="tangent")
    v_paper, _ = course_end_velocity(d, nxt, 1.0, 1.0, rule="paper")
    assert info.rule == "sgc"
    np.testing.assert_array_equal(v, v_paper)


def test_sign_change_threshold_is_k_min():
    """Just inside the cone the tangent is used, just outside it falls back."""
    rules = {}
    for deg in np.arange(60.0, 120.0, 1.0):
        d, nxt = _turn(deg)
        v, info = course_end_velocity(d, nxt, 1.0, 1.0, rule="tangent")
        k = -(info.frame @ (-(d + nxt))) / np.linalg.norm(-(d + nxt))  # direction in S_i
        rules[deg] = info.rule
        if info.rule == "tangent":
            assert np.all(info.k >= K_MIN)
        else:
            assert np.any(k * np.linalg.norm(v) < K_MIN * np.linalg.norm(d) / math.sqrt(3))
    assert "tangent" in rules.values() and "sgc" in rules.values()


def test_tangent_speed_and_a_change_of_pace():
    assert tangent_speed(2.0, 4.0) == 3.0
    assert tangent_speed(1.0, 2.0 * PACE_STEP - 1.0) == pytest.approx(PACE_STEP)
    assert tangent_speed(1.0, 10.0) == PACE_STEP  # graded: at most PACE_STEP times its own
    assert tangent_speed(4.0, 0.0) == 4.0 / PACE_STEP  # and at least 1 / PACE_STEP
    assert tangent_speed(4.0, 3.0) == 3.5


def test_rule_names_are_checked_everywhere():
    d, nxt = _turn(10.0)
    with pytest.raises(ValueError, match="rule must be one of"):
        course_end_velocity(d, nxt, 1.0, 1.0, rule="spline")
    with pytest.raises(ValueError, match="end_rule"):
        PlanOptions(end_rule="spline")
    env = gym.make("SGCRod-v1")
    with pytest.raises(ValueError, match="end_rule"):
        SGCExpert(env, end_rule="spline")
    env.close()


def test_plan_with_the_tangent_rule_is_exact_and_continuous():
    rng = np.random.default_rng(5)
    nails = np.cumsum(rng.normal(size=(6, 3)) * 0.3 + np.array([1.0, 0.3, 0.0]), axis=0)
    times = np.cumsum(rng.uniform(0.4, 1.2, 6))
    goals = [PositionGoal(t, n) for t, n in zip(times, nails, strict=True)]
    state = BodyState(np.array([0.0, 0.0, 1.0]), np.array([0.0, 0.0, 0.0, 1.0]))
    plan = plan_body(state, goals, options=PlanOptions(end_rule="tangent"))
    position_courses = [c for c in plan.courses if c.track == "position"]
    assert [c.rule for c in position_courses[:-1]].count("tangent") >= 3
    previous = np.array([0.0, 0.0, 1.0])
    for i, (t, nail) in enumerate(zip(times, nails, strict=True)):
        np.testing.assert_allclose(plan.sample(t).point_position, nail, atol=1e-12)
        before, after = plan.sample(t - 1e-7), plan.sample(t + 1e-7)
        np.testing.assert_allclose(before.point_velocity, after.point_velocity, atol=1e-4)
        if i < len(nails) - 1 and position_courses[i].rule == "tangent":
            chord = nails[i + 1] - previous
            v = plan.sample(t).point_velocity
            assert np.dot(v, chord) / (np.linalg.norm(v) * np.linalg.norm(chord)) > 1 - 1e-9
        previous = nail


def test_scenario_option_reaches_the_expert():
    assert load_scenario("three_rods").end_velocity_rule == "tangent"
    data = {
        "bodies": [{"name": "b", "shape": "sphere", "size": [0.05], "mass": 1.0,
                    "position": [0, 0, 1], "goals": [{"nail": [1, 0, 1], "time": 0.5}]}],
        "end_velocity_rule": "paper",
    }  # fmt: skip
    assert scenario_from_dict(data).end_velocity_rule == "paper"
    env = gym.make("SGCThreeRods-v2")
    assert SGCExpert(env).model.end_rule == "tangent"
    expert = make_policy("expert-paper", env)
    assert isinstance(expert, EpisodeExpert) and expert.end_rule == "paper"
    assert make_policy("expert", env).end_rule is None  # the scenario's rule
    env.close()


def test_on_the_three_rods_tangent_beats_the_paper_and_stays_exact():
    """The issue's acceptance on the demo scene, through the harness."""
    cards = {p: evaluate(p, "SGCThreeRods-v2", 1, 0).summary for p in ("expert", "expert-paper")}
    for card in cards.values():
        assert card["success_rate"] == 1.0
        assert card["position_error_max"] <= GOAL_TOLERANCE
        assert card["orientation_error_max"] <= GOAL_TOLERANCE
    tangent, paper = cards["expert"], cards["expert-paper"]
    # the graded change of pace trades a little whole-track SPARC (-2.385 against the paper's
    # -2.380; the switch it replaced scored -2.372) for half the largest angular kink
    assert tangent["sparc_track_mean"] > paper["sparc_track_mean"] - 0.01
    assert tangent["goal_speed_ratio_min"] > paper["goal_speed_ratio_min"]
    assert tangent["speed_minima_mean"] < paper["speed_minima_mean"]
    assert tangent["velocity_jump_max"] < paper["velocity_jump_max"]
    assert tangent["acceleration_kink_max"] < paper["acceleration_kink_max"]
    assert tangent["angular_acceleration_kink_max"] < paper["angular_acceleration_kink_max"]


@pytest.mark.slow
def test_on_50_held_out_rod_seeds_tangent_beats_the_paper_and_stays_exact():
    cards = {
        p: evaluate(p, "SGCRod-v1", 50, 10000).summary
        for p in ("expert", "expert-paper", "minimum-jerk")
    }
    for name in ("expert", "expert-paper"):
        assert cards[name]["success_rate"] == 1.0
        assert cards[name]["position_error_max"] <= GOAL_TOLERANCE
        assert cards[name]["orientation_error_max"] <= GOAL_TOLERANCE
    tangent, paper = cards["expert"], cards["expert-paper"]
    assert tangent["sparc_track_mean"] > paper["sparc_track_mean"]
    assert tangent["goal_speed_ratio_min"] > paper["goal_speed_ratio_min"]
    assert math.isfinite(cards["minimum-jerk"]["sparc_track_mean"])


def test_sgc_env_registers_what_the_policies_use():
    assert "SGCThreeRods-v2" in sgc_env.ENV_IDS
