"""Properties of one SGC course component (sgc_env.paper.course)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, example, given, settings
from hypothesis import strategies as st
from scipy.integrate import solve_ivp

from sgc_env.paper import course as course_mod
from sgc_env.paper.course import (
    CourseProfile,
    HermiteProfile,
    HoldProfile,
    solve_batch,
)

gamma_t = st.one_of(
    st.floats(-50.0, 50.0),
    st.sampled_from([-50.0, -20.0, -1.0, 0.0, 1.0, 50.0]),
)
log_k = st.floats(math.log(0.01), math.log(100.0))
d0s = st.one_of(st.floats(1e-3, 1e3), st.floats(-1e3, -1e-3))
durations = st.floats(1e-2, 1e2)


def _make(gt: float, lk: float, d0: float, T: float) -> CourseProfile:
    return CourseProfile.solve(d0, gt * d0 / T, T, math.exp(lk))


@settings(max_examples=300, deadline=None)
@given(gamma_t, log_k, d0s, durations)
@example(gt=49.0, lk=0.0, d0=669.1957586718959, T=1.0)  # y rounds onto the table's last node
def test_end_and_start_conditions(gt, lk, d0, T):
    c = _make(gt, lk, d0, T)
    d_end, v_end, _ = c.state(T)
    assert abs(d_end) <= 1e-12 * abs(d0)
    assert v_end == pytest.approx(-c.k * d0 / T, rel=1e-9)
    d_start, v_start, _ = c.state(0.0)
    assert d_start == pytest.approx(d0, rel=1e-12)
    scale = abs(c.v0) + abs(d0) / T
    assert abs(v_start - c.v0) <= 1e-9 * scale
    # array evaluation agrees with the scalar fast path
    d_arr, v_arr, a_arr = c.evaluate(np.array([0.0, 0.3 * T, T]))
    assert d_arr[0] == pytest.approx(d_start, rel=1e-12)
    assert v_arr[2] == pytest.approx(v_end, rel=1e-12)
    assert a_arr[1] == pytest.approx(c.state(0.3 * T)[2], rel=1e-9, abs=1e-9 * scale / T)


@settings(max_examples=200, deadline=None)
@given(gamma_t, log_k, d0s, durations)
def test_no_overshoot_and_finite(gt, lk, d0, T):
    c = _make(gt, lk, d0, T)
    t = np.linspace(0.0, T, 4001)[:-1]
    d, v, a = c.evaluate(t)
    assert np.all(np.isfinite(d)) and np.all(np.isfinite(v)) and np.all(np.isfinite(a))
    assert np.all(np.sign(d0) * d > 0.0)


@settings(max_examples=60, deadline=None)
@given(st.floats(-3.0, 5.0), st.floats(math.log(0.2), math.log(5.0)), d0s, durations)
def test_closed_form_matches_ode_integration(gt, lk, d0, T):
    c = _make(gt, lk, d0, T)
    # integrating the ODE amplifies errors like exp(aT + sqrt(-z)): compare where it is stable
    assume(abs(c.alpha * T) + math.sqrt(abs(c.z)) <= 6.0)
    q = c.alpha * c.alpha + c.beta_squared

    def rhs(_t, x):
        return [x[1], 2.0 * c.alpha * x[1] - q * x[0]]

    t_eval = np.linspace(0.0, T, 9)
    sol = solve_ivp(rhs, (0.0, T), [d0, c.v0], t_eval=t_eval, rtol=1e-11, atol=1e-13 * abs(d0),
                    method="DOP853")
    d, v, _ = c.evaluate(t_eval)
    np.testing.assert_allclose(sol.y[0], d, rtol=0, atol=1e-7 * abs(d0))
    np.testing.assert_allclose(sol.y[1], v, rtol=0, atol=1e-7 * (abs(d0) / T + abs(c.v0)))


def test_acceleration_is_derivative_of_velocity():
    for gt, k in [(0.5, 1.0), (-5.0, 0.8), (math.log(2.0) - 1.0, 2.0), (20.0, 0.1)]:
        c = CourseProfile.solve(2.0, gt * 2.0 / 3.0, 3.0, k)
        t = np.linspace(0.1, 2.9, 7)
        h = 1e-6
        fd_v = (c.position(t + h) - c.position(t - h)) / (2 * h)
        fd_a = (c.velocity(t + h) - c.velocity(t - h)) / (2 * h)
        np.testing.assert_allclose(c.velocity(t), fd_v, rtol=1e-6, atol=1e-7)
        np.testing.assert_allclose(c.acceleration(t), fd_a, rtol=1e-5, atol=1e-5)


def test_branches_each_hit():
    osc = CourseProfile.solve(1.0, 0.0, 1.0, 1.0)
    assert osc.branch == "oscillatory" and osc.z > 0 and osc.beta_squared > 0
    over = CourseProfile.solve(1.0, -5.0, 1.0, 0.8)
    assert over.branch == "overdamped" and over.z < 0 and over.beta_squared < 0
    # critical: gamma T = log k - 1 gives z = 0 exactly
    crit = CourseProfile.solve(1.0, math.log(2.0) - 1.0, 1.0, 2.0)
    assert crit.branch == "critical" and abs(crit.z) <= course_mod.CRITICAL_TOLERANCE
    assert crit.alpha == pytest.approx(math.log(2.0))
    # smooth through the critical point
    eps = 1e-7
    lo = CourseProfile.solve(1.0, math.log(2.0) - 1.0 - eps, 1.0, 2.0)
    hi = CourseProfile.solve(1.0, math.log(2.0) - 1.0 + eps, 1.0, 2.0)
    assert lo.branch == "overdamped" and hi.branch == "oscillatory"
    t = np.linspace(0, 1, 11)
    np.testing.assert_allclose(lo.position(t), crit.position(t), atol=1e-6)
    np.testing.assert_allclose(hi.position(t), crit.position(t), atol=1e-6)


def test_paper_example_large_alpha():
    # method notes: gamma T = -5, k = 0.8 gives aT = 54.4, z = -3524, D between 0 and D0
    c = CourseProfile.solve(1.0, -5.0, 1.0, 0.8)
    assert c.alpha == pytest.approx(54.4, abs=0.05)
    assert c.z == pytest.approx(-3524, rel=1e-3)
    d = c.position(np.linspace(0, 1, 10001))
    assert np.all((d >= 0) & (d <= 1.0))


def test_extreme_alpha_t_is_finite():
    # |aT| about 1000 and the limit of the representable range
    for gt in (-7.6, -50.0, -340.0):
        c = CourseProfile.solve(1.0, gt, 1.0, 1.0)
        d, v, a = c.evaluate(np.linspace(0, 1, 1001))
        assert np.all(np.isfinite(d)) and np.all(np.isfinite(v)) and np.all(np.isfinite(a))
        assert math.isfinite(c.alpha) and math.isfinite(c.beta_squared)
        assert c.velocity(0.0) == pytest.approx(gt, rel=1e-9)
    assert abs(CourseProfile.solve(1.0, -7.6, 1.0, 1.0).alpha) > 990
    c = CourseProfile.solve(1.0, 1e6, 1.0, 1.0)  # starts moving away very fast
    assert c.branch == "oscillatory" and c.velocity(0.0) == pytest.approx(1e6, rel=1e-9)
    assert np.all(c.position(np.linspace(0, 1, 1001)[:-1]) > 0)


def test_time_consistency_of_resolve():
    for gt, k in [(0.7, 1.3), (-4.0, 0.5), (3.0, 0.2), (-30.0, 2.0)]:
        T, d0 = 2.0, -1.5
        c = CourseProfile.solve(d0, gt * d0 / T, T, k)
        v_end = -k * d0 / T
        for t in (0.3, 1.0, 1.7):
            d, v, _ = c.state(t)
            rest = T - t
            c2 = CourseProfile.solve(d, v, rest, -v_end * rest / d)
            assert c2.alpha == pytest.approx(c.alpha, rel=1e-8, abs=1e-9)
            assert c2.beta_squared == pytest.approx(c.beta_squared, rel=1e-7, abs=1e-8)
            s = np.linspace(0.0, rest, 7)
            np.testing.assert_allclose(c2.position(s), c.position(t + s), rtol=1e-9,
                                       atol=1e-12)


def test_bracket_contains_root_and_table_is_accurate():
    ys = np.concatenate([np.linspace(-340, 200, 20001), [-1.0, -1 - 1e-12, -1 + 1e-12]])
    for y in ys:
        xi = course_mod._solve_xi(float(y))
        lo, hi = course_mod._bracket(float(y))
        assert lo - 1e-12 <= xi <= hi + 1e-12
        f = (course_mod._over_eval(xi) if xi <= 0 else course_mod._osc_eval(xi))[0]
        assert abs(f - y) <= 1e-13 * (1 + abs(y))


def test_batch_matches_scalar():
    rng = np.random.default_rng(3)
    n = 500
    d0 = rng.uniform(0.1, 3.0, n) * rng.choice([-1, 1], n)
    T = rng.uniform(0.1, 5.0, n)
    gt = rng.uniform(-60, 60, n)
    gt[:3] = [np.log(2.0) - 1.0, 0.0, -1.0]
    k = np.exp(rng.uniform(np.log(0.01), np.log(100), n))
    k[:3] = [2.0, 1.0, 1.0]
    b = solve_batch(d0, gt * d0 / T, T, k)
    t = T * 0.37
    d, v, a = b.evaluate(t)
    for i in range(n):
        c = CourseProfile.solve(d0[i], gt[i] * d0[i] / T[i], T[i], k[i])
        assert b.alpha[i] == pytest.approx(c.alpha, rel=1e-9, abs=1e-9)
        assert b.beta_squared[i] == pytest.approx(c.beta_squared, rel=1e-8, abs=1e-9)
        assert course_mod.BRANCH_CODES[c.branch] == b.branch[i]
        ds, vs, _ = c.state(t[i])
        assert d[i] == pytest.approx(ds, rel=1e-9, abs=1e-12)
        assert v[i] == pytest.approx(vs, rel=1e-8, abs=1e-9)
    assert b.branch_names()[0] == "critical"
    dT, vT, _ = b.evaluate(T)
    np.testing.assert_allclose(dT, 0.0, atol=1e-12)
    np.testing.assert_allclose(vT, -k * d0 / T, rtol=1e-9)


@pytest.mark.parametrize(
    "args, field",
    [
        ((0.0, 1.0, 1.0, 1.0), "d0"),
        ((1.0, 1.0, 0.0, 1.0), "duration"),
        ((1.0, 1.0, -2.0, 1.0), "duration"),
        ((1.0, 1.0, 1.0, 0.0), "k"),
        ((1.0, 1.0, 1.0, -1.0), "k"),
        ((math.nan, 1.0, 1.0, 1.0), "d0"),
        ((1.0, math.inf, 1.0, 1.0), "v0"),
        ((1.0, 1.0, math.nan, 1.0), "duration"),
        ((1.0, 1.0, 1.0, math.inf), "k"),
    ],
)
def test_invalid_inputs_name_the_argument(args, field):
    with pytest.raises(ValueError, match=field):
        CourseProfile.solve(*args)
    with pytest.raises(ValueError, match=field):
        solve_batch(*[np.array([1.0, a]) for a in args])


def test_unrepresentable_speeds_are_rejected():
    for v0 in (-400.0, 1e13, 1e300):
        with pytest.raises(ValueError, match="gamma"):
            CourseProfile.solve(1.0, v0, 1.0, 1.0)
        with pytest.raises(ValueError, match="element 1: gamma"):
            solve_batch(1.0, [0.0, v0], 1.0, 1.0)
    c = CourseProfile.solve(1.0, 1e12, 1.0, 1.0)
    assert c.velocity(0.0) == pytest.approx(1e12, rel=1e-9)
    assert c.position(1.0) == 0.0 and c.velocity(1.0) == pytest.approx(-1.0)


def test_rest_arrival_and_hold():
    r = HermiteProfile(2.0, -1.0, 1.5)
    assert r.state(0.0) == pytest.approx((2.0, -1.0, r.acceleration(0.0)))
    assert r.position(1.5) == pytest.approx(0.0, abs=1e-15)
    assert r.velocity(1.5) == pytest.approx(0.0, abs=1e-15)
    # time consistent: re-fit from a state on the curve
    d, v, _ = r.state(0.6)
    r2 = HermiteProfile(d, v, 0.9)
    np.testing.assert_allclose(r2.position(np.linspace(0, 0.9, 5)),
                               r.position(0.6 + np.linspace(0, 0.9, 5)), atol=1e-14)
    e = HermiteProfile(0.0, 0.5, 2.0, -0.25)
    assert e.state(2.0)[0] == pytest.approx(0.0, abs=1e-15)
    assert e.velocity(2.0) == pytest.approx(-0.25) and e.velocity(0.0) == pytest.approx(0.5)
    h = HoldProfile(1.0)
    assert h.state(0.3) == (0.0, 0.0, 0.0)
    assert h.position(np.zeros(3)).shape == (3,)
