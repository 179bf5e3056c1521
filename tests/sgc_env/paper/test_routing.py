"""Routing-time allocation (sgc_env.paper.routing)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from sgc_env.paper.routing import allocate_course_durations, resolve_goal_times

pos = st.floats(1e-3, 1e3)


@settings(max_examples=200, deadline=None)
@given(st.lists(st.tuples(pos, pos), min_size=1, max_size=12), st.floats(1e-2, 1e4))
def test_durations_sum_exactly_and_follow_weight_ratios(pairs, total):
    d = np.array([p[0] for p in pairs])
    w = np.array([p[1] for p in pairs])
    t = allocate_course_durations(d, w, total)
    assert np.all(t > 0)
    assert math.fsum(t) == total  # the exactly rounded sum is the segment's time
    speeds = d / t
    np.testing.assert_allclose(speeds / speeds[0], w / w[0], rtol=1e-9)


def test_resolve_goal_times_anchors_and_allocation():
    times = [None, None, 3.0, None, 5.0]
    critical = [False, False, True, False, True]
    dist = [1.0, 2.0, 1.0, 4.0, 4.0]
    weights = [1.0, 1.0, 2.0, 1.0, 1.0]
    out = resolve_goal_times(times, critical, dist, weights, start_time=1.0)
    assert out[2] == 3.0 and out[4] == 5.0
    durations = np.diff(np.concatenate(([1.0], out)))
    # segment 1: shares 1/1 : 2/1 : 1/2 of 2 s
    np.testing.assert_allclose(durations[:3], np.array([1.0, 2.0, 0.5]) * 2.0 / 3.5)
    np.testing.assert_allclose(durations[3:], [1.0, 1.0])
    np.testing.assert_allclose((np.array(dist) / durations)[:3] / np.array(weights)[:3],
                               1.75, rtol=1e-12)


def test_all_critical_is_identity():
    out = resolve_goal_times([0.5, 1.0, 2.5], [True] * 3, [1, 1, 1], [1, 1, 1])
    np.testing.assert_array_equal(out, [0.5, 1.0, 2.5])


@pytest.mark.parametrize(
    "times, critical, dist, weights, message",
    [
        ([], [], [], [], "empty"),
        ([1.0, 1.0], [True, True], [1, 1], [1, 1], "goal 1: time"),
        ([2.0, 1.0], [True, True], [1, 1], [1, 1], "goal 1: time"),
        ([0.0], [True], [1], [1], "goal 0: time"),
        ([-1.0], [True], [1], [1], "goal 0: time"),
        ([math.nan], [True], [1], [1], "goal 0"),
        ([None], [True], [1], [1], "goal 0"),
        ([None, 2.0], [False, True], [1, 1], [0.0, 1], "goal 0: routing weight"),
        ([None, 2.0], [False, True], [1, 1], [math.inf, 1], "goal 0: routing weight"),
        ([None, 2.0], [False, True], [0.0, 1], [1, 1], "goal 0: course length"),
        ([None, 2.0], [False, True], [math.nan, 1], [1, 1], "goal 0: course length"),
        ([1.0, None], [True, False], [1, 1], [1, 1], "goal 1: the last goal"),
        ([1.0, 2.0], [True, False], [1, 1], [1, 1], "goal 1: has time"),
    ],
)
def test_bad_input_names_the_goal(times, critical, dist, weights, message):
    with pytest.raises(ValueError, match=message):
        resolve_goal_times(times, critical, dist, weights)


@pytest.mark.parametrize(
    "dist, weights, total, message",
    [
        ([1.0], [0.0], 1.0, "weights"),
        ([1.0], [-1.0], 1.0, "weights"),
        ([0.0], [1.0], 1.0, "distances"),
        ([1.0], [1.0], 0.0, "total_time"),
        ([1.0], [1.0], math.inf, "total_time"),
        ([], [], 1.0, "distances"),
        ([1.0], [1.0, 2.0], 1.0, "weights"),
    ],
)
def test_allocate_bad_input(dist, weights, total, message):
    with pytest.raises(ValueError, match=message):
        allocate_course_durations(dist, weights, total)
