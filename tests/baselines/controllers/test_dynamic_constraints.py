"""Dynamic-constraints baseline: closed form, feedback law, tau rule, Figure 1."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from baselines.controllers.dynamic_constraints import (
    DynamicConstraintsCourse,
    choose_tau,
    desired_acceleration,
    simulate,
)

H = 1 / 240

# method-notes table: (tau, eps) -> (met at, speed when met, decimals the speed is stated to).
FIGURE_1 = [
    (0.05, 1e-3, 0.50, 0.016, 3),
    (0.10, 1e-3, 0.96, 0.008, 3),
    (0.10, 1e-4, 1.24, 0.0008, 4),
    (0.20, 1e-3, 1.89, 0.004, 3),
]


@pytest.mark.parametrize(("tau", "eps", "met_at", "speed", "decimals"), FIGURE_1)
def test_figure_1_unit_course_from_rest(tau, eps, met_at, speed, decimals):
    run = simulate([1.0], [0.0], [[0.0]], tau, eps, H, 3.0)
    assert round(run.met_times[0], 2) == met_at
    assert round(run.met_speeds[0], decimals) == speed
    # The continuous law is even earlier; the discrete step lags it by a few percent.
    exact = DynamicConstraintsCourse([1.0], [0.0], tau).time_to_tolerance(eps)
    assert exact < run.met_times[0] < 1.1 * exact


def test_met_speed_is_far_below_the_course_average():
    run = simulate([1.0, 0.0, 0.0], [0.0, 0.0, 0.0], [[0.0, 0.0, 0.0]], 0.1, 1e-3, H, 3.0)
    average_needed = 1.0 / run.met_times[0]
    assert run.met_speeds[0] < 0.01 * average_needed


def test_closed_form_satisfies_the_law_and_initial_conditions():
    course = DynamicConstraintsCourse([1.0, -0.5, 0.2], [0.3, 2.0, 0.0], 0.2)
    t = np.linspace(0.0, 1.5, 31)
    assert np.allclose(course.position(0.0), [1.0, -0.5, 0.2])
    assert np.allclose(course.velocity(0.0), [0.3, 2.0, 0.0])
    h = 1e-6
    numeric_v = (course.position(t + h) - course.position(t - h)) / (2 * h)
    numeric_a = (course.velocity(t + h) - course.velocity(t - h)) / (2 * h)
    assert np.allclose(numeric_v, course.velocity(t), atol=1e-7)
    assert np.allclose(numeric_a, course.acceleration(t), atol=1e-6)
    law = desired_acceleration(course.position(t), course.velocity(t), 0.2)
    assert np.allclose(law, course.acceleration(t))


@settings(max_examples=60, deadline=None)
@given(
    d0=st.lists(st.floats(-2, 2), min_size=3, max_size=3),
    v0=st.lists(st.floats(-5, 5), min_size=3, max_size=3),
    tau=st.floats(0.02, 1.0),
    eps=st.floats(1e-4, 1e-2),
)
def test_time_to_tolerance_is_the_first_crossing(d0, v0, tau, eps):
    course = DynamicConstraintsCourse(d0, v0, tau)
    t_hit = course.time_to_tolerance(eps)
    if np.linalg.norm(d0) <= eps:
        assert t_hit == 0.0
        return
    assert np.linalg.norm(course.position(t_hit)) == pytest.approx(eps, rel=1e-8)
    grid = np.linspace(0.0, t_hit, 2001)[:-1]
    assert np.all(np.linalg.norm(course.position(grid), axis=1) >= eps * (1 - 1e-9))


def test_time_to_tolerance_finds_an_early_dip():
    # The line d0 + c t passes close to the origin early; |D| dips below eps, rises, decays.
    course = DynamicConstraintsCourse([1.0, 0.0], [-10.0 - 1.0 / 0.5, 0.02], 0.5)
    t_hit = course.time_to_tolerance(0.05)
    assert t_hit < 0.12


def test_choose_tau_meets_the_goal_at_the_nominal_time_from_rest():
    for duration, distance, eps in [(1.0, 1.0, 1e-3), (0.4, 0.2, 1e-4), (2.0, 3.0, 1e-2)]:
        tau = choose_tau(duration, distance, eps)
        x = duration / tau
        assert (1 + x) * math.exp(-x) == pytest.approx(eps / distance, rel=1e-10)
        course = DynamicConstraintsCourse([distance, 0.0, 0.0], [0.0, 0.0, 0.0], tau)
        assert course.time_to_tolerance(eps) == pytest.approx(duration, rel=1e-9)


def test_simulate_walks_through_goals_in_order():
    nails = [[1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]
    run = simulate([0.0, 0.0], [0.0, 0.0], nails, [0.1, 0.1, 0.1], 1e-3, H, 5.0)
    assert np.all(np.diff(run.met_times) > 0)
    assert np.all(run.met_speeds < 0.05)
    assert np.linalg.norm(run.positions[-1] - nails[-1]) < 1e-3
    assert run.times.shape[0] == run.positions.shape[0] == run.accelerations.shape[0]


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda: DynamicConstraintsCourse([1.0], [0.0], 0.0), "tau"),
        (lambda: DynamicConstraintsCourse([1.0, 2.0], [0.0], 0.1), "d0"),
        (lambda: DynamicConstraintsCourse([math.nan], [0.0], 0.1), "d0"),
        (lambda: DynamicConstraintsCourse([], [], 0.1), "d0"),
        (lambda: desired_acceleration([1.0, 2.0], [1.0], 0.1), "deviation"),
        (lambda: choose_tau(1.0, 1e-4, 1e-3), "distance"),
        (lambda: choose_tau(-1.0, 1.0, 1e-3), "duration"),
        (lambda: simulate([0.0], [0.0], [], 0.1, 1e-3, H, 1.0), "targets"),
        (lambda: simulate([0.0], [0.0], [[1.0]], [0.1, 0.2], 1e-3, H, 1.0), "taus"),
        (lambda: simulate([0.0], [0.0], [[1.0, 2.0]], 0.1, 1e-3, H, 1.0), "target"),
    ],
)
def test_bad_input_raises_value_error(call, match):
    with pytest.raises(ValueError, match=match):
        call()
