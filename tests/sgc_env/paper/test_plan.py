"""Whole-body plans (sgc_env.paper.plan): exactness, continuity, defined edge cases."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from sgc_env.paper.frames import C_LOW, normalized_frame
from sgc_env.paper.plan import (
    BodyState,
    OrientationGoal,
    PlanOptions,
    PositionGoal,
    plan_body,
)

L = 0.8
TIP = np.array([0.0, 0.0, L / 2])
IDENTITY = np.array([0.0, 0.0, 0.0, 1.0])


def _state(v=(0.0, 0.0, 0.0), w=(0.0, 0.0, 0.0), q=IDENTITY):
    return BodyState(
        np.array([0.0, 0.0, 1.0]), np.asarray(q, float), np.asarray(v, float), np.asarray(w, float)
    )


def _rod_plan():
    nails = [(0.5, 0.2, 1.3), (1.2, 0.5, 1.4), (1.9, 0.6, 1.2), (2.4, 1.2, 1.0)]
    pos = [
        PositionGoal(t, np.array(n), TIP) for t, n in zip((0.7, 1.3, 2.1, 3.0), nails, strict=True)
    ]
    ori = [
        OrientationGoal(1.0, orientation=Rotation.from_rotvec([0.3, 0.2, 0.1]).as_quat()),
        OrientationGoal(2.0, relative_rotation=np.array([0.0, 0.0, 2.0])),
        OrientationGoal(3.0, orientation=Rotation.from_rotvec([0.0, 0.5, 0.0]).as_quat()),
    ]
    return plan_body(_state(v=(0.2, 0.0, 0.1), w=(0.0, 0.3, 0.0)), pos, ori), pos, ori


def test_tip_on_nail_and_orientations_exact_at_goal_times():
    plan, pos, ori = _rod_plan()
    for g in pos:
        s = plan.sample(g.time)
        tip = s.position + Rotation.from_quat(s.orientation).apply(g.point)
        np.testing.assert_allclose(tip, g.nail, atol=1e-9)
        np.testing.assert_allclose(s.point_position, g.nail, atol=1e-12)
    for g, q in zip(ori, plan.goal_orientations(), strict=True):
        s = plan.sample(g.time)
        err = (Rotation.from_quat(s.orientation) * Rotation.from_quat(q).inv()).magnitude()
        assert err <= 1e-9
    first = Rotation.from_quat(plan.goal_orientations()[0])
    second = Rotation.from_quat(plan.goal_orientations()[1])
    assert (second * first.inv()).magnitude() == pytest.approx(2.0)


def test_initial_state_reproduced():
    plan, _, _ = _rod_plan()
    s = plan.sample(0.0)
    np.testing.assert_allclose(s.position, [0, 0, 1.0], atol=1e-12)
    np.testing.assert_allclose(s.velocity, [0.2, 0.0, 0.1], atol=1e-9)
    np.testing.assert_allclose(s.angular_velocity, [0.0, 0.3, 0.0], atol=1e-9)


def test_position_and_velocity_continuous_at_goals():
    plan, pos, ori = _rod_plan()
    h = 1e-7
    for t in sorted({g.time for g in pos} | {g.time for g in ori}):
        a, b = plan.sample(t), plan.sample(t + h)
        bound = 10.0 * h * (1 + np.abs(a.acceleration).max() + np.abs(b.acceleration).max())
        np.testing.assert_allclose(b.position, a.position, atol=bound)
        np.testing.assert_allclose(b.velocity, a.velocity, atol=bound)
        np.testing.assert_allclose(b.angular_velocity, a.angular_velocity, atol=bound)


def test_velocity_and_acceleration_are_derivatives():
    plan, _, _ = _rod_plan()
    h = 1e-6
    for t in (0.3, 0.95, 1.6, 2.5):
        a, b, c = plan.sample(t - h), plan.sample(t), plan.sample(t + h)
        np.testing.assert_allclose((c.position - a.position) / (2 * h), b.velocity, atol=1e-6)
        np.testing.assert_allclose((c.velocity - a.velocity) / (2 * h), b.acceleration, atol=1e-4)
        w_fd = Rotation.from_quat(c.orientation) * Rotation.from_quat(a.orientation).inv()
        np.testing.assert_allclose(w_fd.as_rotvec() / (2 * h), b.angular_velocity, atol=1e-6)
        np.testing.assert_allclose(
            (c.angular_velocity - a.angular_velocity) / (2 * h),
            b.angular_acceleration,
            atol=1e-4,
        )


def test_end_velocity_between_averages_within_paper_assumption():
    rng = np.random.default_rng(2)
    checked = 0
    for _ in range(20):
        nails = np.cumsum(rng.normal(size=(6, 3)) * 0.1 + np.array([1.0, 0.3, 0.0]), axis=0)
        times = np.cumsum(rng.uniform(0.4, 1.2, 6))
        goals = [PositionGoal(t, n) for t, n in zip(times, nails, strict=True)]
        plan = plan_body(_state(), goals, options=PlanOptions(end_rule="paper"))
        starts = [np.array([0, 0, 1.0]) - nails[0]] + [nails[i] - nails[i + 1] for i in range(5)]
        durations = np.diff(np.concatenate(([0.0], times)))
        for c in plan.courses:
            i = c.index
            if c.rule != "sgc" or not c.within_paper_assumption:
                continue
            frame = normalized_frame(starts[i], starts[i + 1])
            speed = -(frame @ plan.sample(times[i]).point_velocity)
            avg_i = np.linalg.norm(starts[i]) / math.sqrt(3) / durations[i]
            avg_n = (frame @ starts[i + 1]) / durations[i + 1]
            assert np.all(speed >= np.minimum(avg_i, C_LOW * avg_n) - 1e-9)
            assert np.all(speed <= np.maximum(avg_i, avg_n) + 1e-9)
            checked += 1
    assert checked > 20


def test_somersault_completes_with_the_right_angle():
    axis = np.array([1.0, 0.0, 1.0]) / math.sqrt(2)
    rel = 1.5 * 2 * math.pi * axis
    plan = plan_body(_state(), [], [OrientationGoal(2.0, relative_rotation=rel)])
    # a smooth split: 3 pi in 24 courses of about pi / 8, evenly timed, all reporting goal 0
    assert [(c.t_start, c.t_end, c.index) for c in plan.courses] == [
        (2.0 * i / 24, 2.0 * (i + 1) / 24, 0) for i in range(24)
    ]
    assert len(plan.goal_orientations()) == 1
    t = np.linspace(0.0, 2.0, 4001)
    w_axis = np.array([plan.sample(x).angular_velocity @ axis for x in t])
    total = float(np.sum(0.5 * (w_axis[1:] + w_axis[:-1]) * np.diff(t)))
    # each sub-course bends slightly off the axis in its normalised frame (k per component)
    assert total == pytest.approx(3 * math.pi, rel=1e-4)
    assert np.all(w_axis[1:] > 0)  # no back-turning
    final = Rotation.from_quat(plan.sample(2.0).orientation)
    assert (final * Rotation.from_rotvec(rel).inv()).magnitude() <= 1e-9


def test_somersault_keeps_an_initial_spin_across_its_axis():
    # A whole turn as one course would start on |phi| = 2 pi, where J_l cannot represent the
    # spin across the axis: the plan would start at the wrong angular velocity.
    w0 = np.array([0.0, 2.0, 1.0])
    rel = np.array([2 * math.pi, 0.0, 0.0])
    goals = [
        OrientationGoal(1.0, relative_rotation=rel),
        OrientationGoal(1.5, orientation=IDENTITY),
    ]
    plan = plan_body(_state(w=w0), [], goals)
    np.testing.assert_allclose(plan.sample(0.0).angular_velocity, w0, atol=1e-12)
    t = np.linspace(0.0, 1.5, 6001)
    w = np.array([plan.sample(x).angular_velocity for x in t])
    assert np.abs(np.diff(w, axis=0)).max() < 0.05  # continuous: no jump at any course start
    for k in range(0, t.size - 1, 50):  # the orientation integrates the angular velocity
        step = (
            Rotation.from_quat(plan.sample(t[k + 1]).orientation)
            * Rotation.from_quat(plan.sample(t[k]).orientation).inv()
        )
        np.testing.assert_allclose(
            step.as_rotvec(), 0.5 * (w[k] + w[k + 1]) * (t[1] - t[0]), atol=1e-6
        )
    final = Rotation.from_quat(plan.sample(1.0).orientation)
    assert final.magnitude() <= 1e-9  # a whole turn about x returns to the identity
    assert len(plan.goal_orientations()) == 2


def test_point_change_between_goals_keeps_com_continuous():
    pos = [
        PositionGoal(1.0, np.array([0.5, 0.0, 1.2]), TIP),
        PositionGoal(2.0, np.array([1.0, 0.5, 0.6]), -TIP),
    ]
    ori = [OrientationGoal(1.5, orientation=Rotation.from_rotvec([0.4, 0.0, 0.0]).as_quat())]
    plan = plan_body(_state(w=(0.5, 0.0, 0.0)), pos, ori)
    a, b = plan.sample(1.0), plan.sample(1.0 + 1e-8)
    np.testing.assert_allclose(a.position, b.position, atol=1e-6)
    np.testing.assert_allclose(a.velocity, b.velocity, atol=1e-5)
    s = plan.sample(2.0)
    tip = s.position + Rotation.from_quat(s.orientation).apply(-TIP)
    np.testing.assert_allclose(tip, pos[1].nail, atol=1e-9)


def test_repeated_nail_is_a_dwell_after_arriving_at_rest():
    nail = np.array([1.0, 0.0, 1.0])
    pos = [PositionGoal(1.0, nail), PositionGoal(1.5, nail), PositionGoal(2.5, nail + 1.0)]
    plan = plan_body(_state(v=(0.3, 0, 0)), pos)
    assert plan.courses[0].rule == "rest" and plan.courses[1].rule == "dwell"
    np.testing.assert_allclose(plan.sample(1.0).velocity, 0.0, atol=1e-12)
    for t in (1.1, 1.3, 1.5):
        np.testing.assert_allclose(plan.sample(t).position, nail, atol=1e-12)
    np.testing.assert_allclose(plan.sample(2.5).position, nail + 1.0, atol=1e-12)


def test_last_goal_end_velocity_and_extrapolation():
    goal = PositionGoal(1.0, np.array([1.0, 0.0, 1.0]))
    plan = plan_body(_state(), [goal])
    np.testing.assert_allclose(plan.sample(1.0).velocity, [1.0, 0.0, 0.0], atol=1e-9)
    np.testing.assert_allclose(plan.sample(1.5).position, [1.5, 0.0, 1.0], atol=1e-9)
    plan = plan_body(_state(), [goal], end_velocity=np.zeros(3))
    np.testing.assert_allclose(plan.sample(1.0).velocity, 0.0, atol=1e-12)
    plan = plan_body(_state(), [goal], end_velocity=np.array([0.5, 0.1, 0.0]))
    np.testing.assert_allclose(plan.sample(1.0).velocity, [0.5, 0.1, 0.0], atol=1e-9)


def test_goal_times_off_any_grid_and_no_orientation_track():
    w0 = np.array([0.0, 0.0, 0.7])
    plan = plan_body(_state(w=w0), [PositionGoal(math.pi / 3, np.array([0.3, 0.1, 1.1]))])
    s = plan.sample(1.0)
    expected = Rotation.from_rotvec(w0 * 1.0)
    assert (Rotation.from_quat(s.orientation) * expected.inv()).magnitude() < 1e-12
    np.testing.assert_allclose(plan.sample(math.pi / 3).point_position, [0.3, 0.1, 1.1], atol=1e-12)


def _ok_goals():
    return [PositionGoal(1.0, np.array([1.0, 0, 0])), PositionGoal(2.0, np.array([2.0, 0, 0]))]


@pytest.mark.parametrize(
    "goals, message",
    [
        ([PositionGoal(0.0, np.ones(3))], "position goal 0: time"),
        ([PositionGoal(-1.0, np.ones(3))], "position goal 0: time"),
        ([PositionGoal(1.0, np.ones(3)), PositionGoal(1.0, np.zeros(3))], "position goal 1: time"),
        ([PositionGoal(2.0, np.ones(3)), PositionGoal(1.0, np.zeros(3))], "position goal 1: time"),
        ([PositionGoal(math.nan, np.ones(3))], "position goal 0: time"),
        ([PositionGoal(1.0, np.array([0, math.nan, 0]))], "position goal 0: nail contains NaN"),
        ([PositionGoal(1.0, np.array([0, math.inf, 0]))], "position goal 0: nail contains inf"),
        ([PositionGoal(1.0, np.ones(3), np.array([math.nan, 0, 0]))], "position goal 0: point"),
        ([PositionGoal(1.0, np.ones(2))], "position goal 0: nail must have shape"),
    ],
)
def test_bad_position_goals(goals, message):
    with pytest.raises(ValueError, match=message):
        plan_body(_state(), goals)


@pytest.mark.parametrize(
    "goal, message",
    [
        (OrientationGoal(1.0), "orientation goal 0: give exactly one"),
        (OrientationGoal(1.0, IDENTITY, np.zeros(3)), "orientation goal 0: give exactly one"),
        (OrientationGoal(1.0, np.zeros(4)), "orientation goal 0: orientation quaternion has zero"),
        (OrientationGoal(1.0, np.array([0, 0, math.nan, 1])), "orientation goal 0: orientation"),
        (
            OrientationGoal(1.0, relative_rotation=np.array([math.inf, 0, 0])),
            "orientation goal 0: relative_rotation contains inf",
        ),
        (OrientationGoal(0.0, IDENTITY), "orientation goal 0: time"),
    ],
)
def test_bad_orientation_goals(goal, message):
    with pytest.raises(ValueError, match=message):
        plan_body(_state(), [], [goal])


def test_bad_state_options_and_empty():
    with pytest.raises(ValueError, match="both empty"):
        plan_body(_state(), [], [])
    with pytest.raises(ValueError, match="initial state: orientation quaternion has zero norm"):
        plan_body(_state(q=np.zeros(4)), _ok_goals())
    bad = BodyState(np.array([0, 0, math.nan]), IDENTITY, np.zeros(3), np.zeros(3))
    with pytest.raises(ValueError, match="initial state: position contains NaN"):
        plan_body(bad, _ok_goals())
    with pytest.raises(ValueError, match="end_velocity"):
        plan_body(_state(), _ok_goals(), end_velocity=np.array([math.nan, 0, 0]))
    with pytest.raises(ValueError, match="c_low"):
        PlanOptions(c_low=0.5)
    with pytest.raises(ValueError, match="k_min"):
        PlanOptions(k_min=0.0)
    plan = plan_body(_state(), _ok_goals())
    with pytest.raises(ValueError, match="t must be"):
        plan.sample(-0.1)


@settings(max_examples=40, deadline=None)
@given(
    st.lists(
        st.tuples(
            st.floats(0.2, 1.5), st.lists(st.floats(-2, 2), min_size=3, max_size=3), st.booleans()
        ),
        min_size=1,
        max_size=5,
    ),
    st.lists(
        st.tuples(st.floats(0.2, 1.5), st.lists(st.floats(-7, 7), min_size=3, max_size=3)),
        max_size=4,
    ),
    st.lists(st.floats(-1, 1), min_size=6, max_size=6),
)
def test_random_rod_plans_are_exact_and_continuous(pos_spec, ori_spec, initial):
    times = np.cumsum([p[0] for p in pos_spec])
    pos = []
    for (
        t,
        (_, nail, repeat),
    ) in zip(times, pos_spec, strict=True):
        nail = pos[-1].nail if (repeat and pos) else np.array(nail)
        pos.append(PositionGoal(float(t), nail, TIP if len(pos) % 2 == 0 else -TIP))
    o_times = np.cumsum([o[0] for o in ori_spec])
    ori = [
        OrientationGoal(float(t), relative_rotation=np.array(r))
        for t, (_, r) in zip(o_times, ori_spec, strict=True)
    ]
    plan = plan_body(_state(v=initial[:3], w=initial[3:]), pos, ori)
    for g in pos:
        s = plan.sample(g.time)
        tip = s.position + Rotation.from_quat(s.orientation).apply(g.point)
        np.testing.assert_allclose(tip, g.nail, atol=1e-9)
    for g, q in zip(ori, plan.goal_orientations(), strict=True):
        err = Rotation.from_quat(plan.sample(g.time).orientation) * Rotation.from_quat(q).inv()
        assert err.magnitude() <= 1e-9
    h = 1e-8
    for t in [g.time for g in pos] + [g.time for g in ori]:
        a, b = plan.sample(t), plan.sample(t + h)
        for x in (a, b):
            assert all(np.all(np.isfinite(f)) for f in (x.position, x.velocity, x.acceleration))
        scale = 1.0 + np.abs(a.acceleration).max() + np.abs(b.acceleration).max()
        np.testing.assert_allclose(b.position, a.position, atol=1e-6 * scale)
        np.testing.assert_allclose(b.velocity, a.velocity, atol=1e-5 * scale)


def test_somersault_on_the_control_grid_splits_as_the_env_does():
    """plan_body and the env's tracks share one splitter: on a control grid the sub-courses
    end on the same ticks (2.05 s at 60 Hz is 123 ticks, not divisible into the smooth
    split's 24 courses); the sub-rotations too."""
    from sgc_env.envs.tracks import compile_tracks
    from sgc_env.scenario import Body, Goal, Scenario, resolve_scenario

    rel = np.array([0.0, 3 * math.pi, 0.0])
    goal = Goal(time=2.05, relative_rotation=tuple(rel))
    body = Body(name="rod", shape="rod", size=(0.8, 0.02), mass=1.0, goals=(goal,))
    tracks = compile_tracks(resolve_scenario(Scenario(bodies=(body,), control_frequency=60)))
    plan = plan_body(
        _state(), [], [OrientationGoal(2.05, relative_rotation=rel)],
        options=PlanOptions(control_frequency=60),
    )  # fmt: skip
    ends = [c.t_end for c in plan.courses]
    assert ends == tracks[0].orientation.times.tolist()
    assert [round(t * 60) for t in ends] == [round(i * 123 / 24) for i in range(1, 25)]
    pieces = np.linalg.norm(tracks[0].orientation.course_start, axis=1)
    assert pieces.sum() == pytest.approx(3 * math.pi, abs=1e-12)
    assert pieces.max() > 2 * pieces.min()  # unequal: from rest up to the average pace
    even = plan_body(_state(), [], [OrientationGoal(2.05, relative_rotation=rel)])
    assert [c.t_end for c in even.courses] != ends  # continuous time: 0.41, 0.82, ...


def test_vectorised_deviations_match_the_samples():
    """BodyPlan.deviations (one vectorised evaluation per course) agrees with sample()."""
    plan, pos, _ = _rod_plan()
    times = np.array([0.05, 0.7, 0.71, 1.5, 2.1, 2.9, 3.0, 3.4])
    d, v, a = plan.deviations(times, "position")
    nails = np.array([pos[min(np.searchsorted([g.time for g in pos], t), 3)].nail for t in times])
    for k, t in enumerate(times):
        s = plan.sample(float(t))
        np.testing.assert_allclose(d[k] + nails[k], s.point_position, atol=1e-12)
        np.testing.assert_allclose(v[k], s.point_velocity, atol=1e-12)
    h = 1e-6  # D'' is the derivative of D' (inside courses)
    for t in (0.3, 1.0, 2.5):
        (v0, v1), acc = plan.deviations(np.array([t - h, t + h]))[1], plan.deviations([t])[2][0]
        np.testing.assert_allclose((v1 - v0) / (2 * h), acc, atol=1e-4)
    # at an orientation goal phi = 0, so J_l = I and omega = phi'
    goal_times = np.array([1.0, 2.0, 3.0])
    phi, phi_dot, _ = plan.deviations(goal_times, "orientation")
    np.testing.assert_allclose(phi, 0.0, atol=1e-12)
    for k, t in enumerate(goal_times):
        np.testing.assert_allclose(phi_dot[k], plan.sample(float(t)).angular_velocity, atol=1e-12)
    with pytest.raises(ValueError, match="track must be"):
        plan.deviations(times, "spin")
