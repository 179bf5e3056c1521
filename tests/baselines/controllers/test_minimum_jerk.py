"""Minimum-jerk spline baseline: interpolation, continuity, the classic stroke, rotations."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.interpolate import BSpline, PPoly
from scipy.spatial.transform import Rotation

from baselines.controllers.minimum_jerk import MinimumJerkPath, MinimumJerkRotation

TIMES = np.array([0.0, 0.7, 1.5, 2.0, 3.1])
POINTS = np.random.default_rng(1).normal(size=(5, 3))


def test_passes_through_every_point_at_its_time():
    path = MinimumJerkPath(TIMES, POINTS, [0.3, 0.0, -0.2], a0=[0.0, 1.0, 0.0])
    assert np.max(np.abs(path.position(TIMES) - POINTS)) < 1e-12
    assert np.allclose(path.velocity(0.0), [0.3, 0.0, -0.2], atol=1e-12)
    assert np.allclose(path.acceleration(0.0), [0.0, 1.0, 0.0], atol=1e-12)
    average = (POINTS[-1] - POINTS[-2]) / (TIMES[-1] - TIMES[-2])
    assert np.allclose(path.velocity(TIMES[-1]), average, atol=1e-12)
    assert np.allclose(path.acceleration(TIMES[-1]), 0.0, atol=1e-10)


def test_c2_and_beyond_at_the_knots():
    path = MinimumJerkPath(TIMES, POINTS, np.zeros(3), end_velocity=np.ones(3))
    spline = path._spline
    for axis in range(3):
        pp = PPoly.from_spline(BSpline(spline.t, spline.c[:, axis], spline.k))
        for knot in TIMES[1:-1]:
            j = int(np.searchsorted(pp.x, knot, side="right")) - 1
            assert pp.x[j] == pytest.approx(knot)
            for nu in range(5):
                deriv = pp.derivative(nu) if nu else pp
                left = np.polyval(deriv.c[:, j - 1], knot - pp.x[j - 1])
                right = deriv.c[-1, j]
                assert left == pytest.approx(right, abs=1e-8 * (1 + abs(right)))


def test_single_segment_rest_to_rest_is_the_classic_stroke():
    x0, x1 = np.array([1.0, -2.0]), np.array([3.0, 0.5])
    path = MinimumJerkPath([0.5, 2.5], [x0, x1], [0.0, 0.0], end_velocity=[0.0, 0.0])
    t = np.linspace(0.5, 2.5, 41)
    s = (t - 0.5) / 2.0
    shape = 10 * s**3 - 15 * s**4 + 6 * s**5
    assert np.allclose(path.position(t), x0 + np.outer(shape, x1 - x0), atol=1e-12)


def test_scalar_points_give_scalar_output():
    path = MinimumJerkPath([0.0, 1.0, 2.0], [0.0, 1.0, 0.0], 0.0)
    assert path.position(np.array([0.5, 1.5])).shape == (2,)
    assert path.position(1.0) == pytest.approx(1.0, abs=1e-12)


def test_minimises_jerk_against_a_perturbed_curve():
    times, points = np.array([0.0, 1.0, 2.0]), np.array([[0.0], [1.0], [0.5]])
    path = MinimumJerkPath(times, points, [0.0], end_velocity=[0.0])
    t = np.linspace(0.0, 2.0, 4001)
    cost = np.trapezoid(path.jerk(t)[:, 0] ** 2, t)
    bump = (t * (1 - t) * (2 - t)) ** 3  # zero with two derivatives at every knot
    jerk_bump = np.gradient(np.gradient(np.gradient(bump, t), t), t)
    other = np.trapezoid((path.jerk(t)[:, 0] + 0.1 * jerk_bump) ** 2, t)
    assert cost < other


def test_somersault_rotation_path():
    quats = [[0, 0, 0, 1], [0, 0, 1, 0], [0, 0, 0, 1]]
    path = MinimumJerkRotation([0.0, 1.0, 2.0], quats, [0, 0, 0], rotations=[[0, 0, math.pi]] * 2)
    assert np.allclose(path.rotation_vector([1.0, 2.0]), [[0, 0, math.pi], [0, 0, 2 * math.pi]])
    q = path.orientation(np.array([0.0, 1.0, 2.0]))
    for got, want in zip(q, quats, strict=True):
        assert (Rotation.from_quat(got) * Rotation.from_quat(want).inv()).magnitude() < 1e-12
    assert path.angular_velocity(np.array([1.0]))[0, 2] > 3.0


def test_angular_velocity_matches_finite_differences():
    quats = Rotation.from_rotvec([[0, 0, 0], [0.5, 0.2, 0], [0.9, 1.1, -0.4]]).as_quat()
    path = MinimumJerkRotation([0.0, 1.0, 2.0], quats, [0.2, 0.0, 0.1], end_omega=[0, 0.3, 0])
    h = 1e-6
    for t in (0.3, 1.2, 1.9):
        r_plus = Rotation.from_quat(path.orientation(t + h))
        r_minus = Rotation.from_quat(path.orientation(t - h))
        numeric = (r_plus * r_minus.inv()).as_rotvec() / (2 * h)
        assert np.allclose(numeric, path.angular_velocity(t), atol=1e-6)
    assert np.allclose(path.angular_velocity(0.0), [0.2, 0.0, 0.1], atol=1e-12)
    assert np.allclose(path.angular_velocity(2.0), [0.0, 0.3, 0.0], atol=1e-12)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"times": [], "points": [], "v0": 0.0}, "times"),
        ({"times": [0.0], "points": [[0.0]], "v0": [0.0]}, "times"),
        ({"times": [0.0, 0.0], "points": [[0.0], [1.0]], "v0": [0.0]}, "increasing"),
        ({"times": [0.0, 1.0], "points": [[0.0]], "v0": [0.0]}, "points"),
        ({"times": [0.0, 1.0], "points": [[0.0], [math.nan]], "v0": [0.0]}, "points"),
        ({"times": [0.0, 1.0], "points": [[0.0], [1.0]], "v0": [0.0, 1.0]}, "v0"),
        (
            {"times": [0.0, 1.0], "points": [[0.0], [1.0]], "v0": [0.0], "end_velocity": [1, 2]},
            "end_velocity",
        ),
    ],
)
def test_bad_input_raises_value_error(kwargs, match):
    with pytest.raises(ValueError, match=match):
        MinimumJerkPath(**kwargs)


@settings(max_examples=40, deadline=None)
@given(
    gaps=st.lists(st.floats(0.05, 3.0), min_size=1, max_size=6),
    seed=st.integers(0, 2**32 - 1),
)
def test_random_knots_are_interpolated_exactly(gaps, seed):
    times = np.concatenate([[0.0], np.cumsum(gaps)])
    points = np.random.default_rng(seed).uniform(-2, 2, size=(times.size, 3))
    path = MinimumJerkPath(times, points, np.zeros(3))
    assert np.max(np.abs(path.position(times) - points)) < 1e-10
    assert np.allclose(path.velocity(0.0), 0.0, atol=1e-9)
