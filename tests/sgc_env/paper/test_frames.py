"""Normalized frames, the k rules and mid-course re-solves (sgc_env.paper.frames)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from sgc_env.paper.frames import (
    C_HIGH,
    C_LOW,
    K_MIN,
    choose_k,
    condition_14,
    course_end_velocity,
    next_deviation,
    normalized_frame,
    solve_course_in_frame,
)

vec = st.lists(st.floats(-10, 10), min_size=3, max_size=3).map(np.array)


@settings(max_examples=200, deadline=None)
@given(vec, vec)
def test_frame_properties(d, nxt):
    if np.linalg.norm(d) < 1e-6:
        d = d + np.array([1.0, 0.0, 0.0])
    r = normalized_frame(d, nxt)
    np.testing.assert_allclose(r @ r.T, np.eye(3), atol=1e-12)
    assert np.linalg.det(r) == pytest.approx(1.0)
    np.testing.assert_allclose(r @ d, np.linalg.norm(d) / math.sqrt(3) * np.ones(3), atol=1e-9)
    ds = r @ nxt
    # in the plane of (1,1,1) and (1,0,0): components 2 and 3 equal, component 1 not smaller
    assert ds[1] == pytest.approx(ds[2], abs=1e-9)
    assert ds[0] >= ds[1] - 1e-9


def test_frame_degenerate_next():
    d = np.array([0.0, 0.0, 2.0])
    for nxt in (None, np.zeros(3), 3 * d, -d):
        r = normalized_frame(d, nxt)
        np.testing.assert_allclose(r @ d, 2 / math.sqrt(3) * np.ones(3), atol=1e-12)
    with pytest.raises(ValueError, match="d_start"):
        normalized_frame(np.zeros(3))
    with pytest.raises(ValueError, match="d_next"):
        normalized_frame(d, [np.nan, 0, 0])


def test_choose_k_rules():
    rho = np.array([-1.0, 0.1, 0.5, 0.99, 1.0, 1.02, 2.0])
    k = choose_k(rho)
    assert k[0] == K_MIN and k[1] == pytest.approx(C_LOW * 0.1)
    assert k[2] == pytest.approx(C_LOW * 0.5) and k[3] == pytest.approx(C_LOW * 0.99)
    assert k[4] == 1.0 and k[5] == 1.0 and k[6] == pytest.approx(C_HIGH * 2.0)
    assert C_LOW > 0.8 and C_HIGH < 1.0


def _random_turn(rng, max_angle):
    d = rng.normal(size=3)
    axis = np.cross(d, rng.normal(size=3))
    axis /= np.linalg.norm(axis)
    angle = rng.uniform(0, max_angle)
    nxt = Rotation.from_rotvec(angle * axis).apply(d) * rng.uniform(0.3, 3.0)
    return d, nxt


def test_end_velocity_between_averages_within_paper_assumption():
    """Per component of S_i the end speed lies between the averages of courses i and i+1.

    For rho >= 1 strictly between; for rho < 1 the paper's eq. 12 asks for c > 0.8, so the
    speed lies between c_low times the next average and the current average (c_low = 1 gives
    the closed interval exactly).
    """
    rng = np.random.default_rng(0)
    for _ in range(2000):
        d, nxt = _random_turn(rng, math.pi / 6)
        t_i, t_n = rng.uniform(0.2, 3.0, 2)
        v, info = course_end_velocity(d, nxt, t_i, t_n)
        assert info.rule == "sgc"
        r = info.frame
        speed = -(r @ v)  # per component, positive = towards the goal
        avg_i = np.linalg.norm(d) / math.sqrt(3) / t_i * np.ones(3)
        avg_n = (r @ nxt) / t_n
        assert np.all(avg_n > 0)
        lo = np.minimum(avg_i, C_LOW * avg_n)
        hi = np.maximum(avg_i, avg_n)
        assert np.all(speed >= lo - 1e-12) and np.all(speed <= hi + 1e-12)
        v1, _ = course_end_velocity(d, nxt, t_i, t_n, c_low=1.0)
        s1 = -(r @ v1)
        assert np.all(s1 >= np.minimum(avg_i, avg_n) - 1e-12)
        assert np.all(s1 <= np.maximum(avg_i, avg_n) + 1e-12)
        if info.within_paper_assumption and np.all(info.rho < 1):
            # straight-ish continuation slower than the next average: eq. 14 holds
            assert condition_14(v, nxt, t_n, None) or info.turn_angle > 0


def test_condition_14_on_straight_line():
    d = np.array([1.0, 2.0, 0.5])
    for scale, t_n in ((0.5, 1.0), (2.0, 1.0), (1.0, 0.5)):
        v, info = course_end_velocity(d, scale * d, 1.0, t_n)
        assert info.within_paper_assumption and info.turn_angle == pytest.approx(0.0, abs=1e-7)
        assert condition_14(v, scale * d, t_n, None)


def test_sharp_turn_clamps_and_reports():
    d = np.array([1.0, 0.0, 0.0])
    v, info = course_end_velocity(d, np.array([-1.0, 1.0, 0.0]), 1.0, 1.0)
    assert not info.within_paper_assumption
    assert np.all(info.k >= K_MIN) and np.any(info.k == K_MIN)
    assert info.turn_angle == pytest.approx(3 * math.pi / 4)
    # a sharp turn into a much slower course: the floor scales with the speed ratio
    nxt = np.array([-1.0, 1.0, 0.0]) * 1e-3
    _, info = course_end_velocity(d, nxt, 1.0, 1.0)
    ratio = np.linalg.norm(nxt) / np.linalg.norm(d)
    assert np.min(info.k) == pytest.approx(K_MIN * ratio)
    # moderate turn beyond pi/6 is flagged even when no rho is negative
    nxt = Rotation.from_rotvec([0, 0, 0.7]).apply(d)
    _, info = course_end_velocity(d, nxt, 1.0, 1.0)
    assert not info.within_paper_assumption


def test_last_goal_rules():
    d = np.array([0.3, -0.4, 1.2])
    v, info = course_end_velocity(d, None, 2.0, None)
    np.testing.assert_allclose(v, -d / 2.0)
    assert info.rule == "last" and np.all(info.k == 1.0)
    want = -0.2 * d
    v, info = course_end_velocity(d, None, 2.0, None, end_velocity=want)
    np.testing.assert_allclose(v, want, atol=1e-12)
    assert info.within_paper_assumption
    v, info = course_end_velocity(d, None, 2.0, None, end_velocity=np.zeros(3))
    assert info.rule == "rest" and not np.any(v)
    v, info = course_end_velocity(d, None, 2.0, None, end_velocity=d)  # away from the goal
    assert not info.within_paper_assumption and np.all(info.k == K_MIN)


def test_dwell_rules():
    d = np.array([1.0, 1.0, 0.0])
    v, info = course_end_velocity(d, np.zeros(3), 1.0, 1.0)
    assert info.rule == "rest" and not np.any(v)
    v, info = course_end_velocity(np.zeros(3), d, 1.0, 1.0)
    assert info.rule == "dwell" and not np.any(v)
    c = solve_course_in_frame(None, np.zeros(3), np.zeros(3), 0.5, np.zeros(3))
    assert c.branches == ("dwell",) * 3
    assert not np.any(c.state(0.2)[0])
    # arriving at rest: position and velocity zero at the end
    c = solve_course_in_frame(None, d, np.array([0.1, -0.2, 0.3]), 1.5, np.zeros(3))
    dev, vel, _ = c.state(1.5)
    np.testing.assert_allclose(dev, 0, atol=1e-14)
    np.testing.assert_allclose(vel, 0, atol=1e-14)


@pytest.mark.parametrize(
    "kwargs, field",
    [
        ({"d_start": [np.nan, 0, 0]}, "d_start"),
        ({"d_next": [0, np.inf, 0]}, "d_next"),
        ({"t_course": 0.0}, "t_course"),
        ({"t_course": -1.0}, "t_course"),
        ({"t_next": 0.0}, "t_next"),
        ({"t_next": math.nan}, "t_next"),
    ],
)
def test_bad_inputs_name_the_field(kwargs, field):
    args = {"d_start": [1.0, 0, 0], "d_next": [1.0, 0.1, 0], "t_course": 1.0, "t_next": 1.0}
    args.update(kwargs)
    with pytest.raises(ValueError, match=field):
        course_end_velocity(args["d_start"], args["d_next"], args["t_course"], args["t_next"])


def test_resolve_in_frame_reproduces_the_course():
    rng = np.random.default_rng(5)
    for _ in range(50):
        d, nxt = _random_turn(rng, math.pi / 3)
        T, Tn = rng.uniform(0.3, 2.0, 2)
        v0 = rng.normal(size=3)
        v_end, info = course_end_velocity(d, nxt, T, Tn)
        full = solve_course_in_frame(info.frame, d, v0, T, v_end)
        d0, vv0, _ = full.state(0.0)
        np.testing.assert_allclose(d0, d, atol=1e-12)
        np.testing.assert_allclose(vv0, v0, atol=1e-9)
        dT, vT, _ = full.state(T)
        np.testing.assert_allclose(dT, 0, atol=1e-12)
        np.testing.assert_allclose(vT, v_end, atol=1e-9)
        t = rng.uniform(0.1, 0.9) * T
        dt, vt, _ = full.state(t)
        part = solve_course_in_frame(info.frame, dt, vt, T - t, v_end)
        s = np.linspace(0, T - t, 5)
        np.testing.assert_allclose(part.evaluate(s)[0], full.evaluate(t + s)[0], atol=1e-9)
        for a, b in zip(part.profiles, full.profiles, strict=True):
            assert a.alpha == pytest.approx(b.alpha, rel=1e-7, abs=1e-7)


@pytest.mark.parametrize("case", range(40))
def test_next_deviation_is_the_re_solved_course(case):
    """The expert's plain-float path and solve_course_in_frame share the component rules."""
    rng = np.random.default_rng(case)
    d_start, d_next = rng.normal(size=3), rng.normal(size=3)
    kind = case % 4
    if kind == 1:
        d_next = None  # last goal: arrive at the given end velocity
    v_end, info = course_end_velocity(
        d_start, d_next, 1.0, 0.8, end_velocity=rng.normal(size=3) if kind == 1 else None
    )
    deviation, rate = d_start * rng.uniform(0.1, 1.0), rng.normal(size=3)
    if kind == 2:
        v_end = np.zeros(3)  # arrive at rest: Hermite components
    if kind == 3:
        deviation, rate, v_end, info = np.zeros(3), np.zeros(3), np.zeros(3), None  # dwell
    frame = None if info is None else info.frame
    course = solve_course_in_frame(frame, deviation, rate, 0.5, v_end)
    rows = tuple(map(tuple, np.eye(3) if frame is None else frame))
    fast = next_deviation(
        rows, tuple(deviation), tuple(rate), 0.5, tuple(v_end.tolist()), 1.0 / 60.0
    )
    assert np.array_equal(np.array(fast), course.state(1.0 / 60.0)[0])
