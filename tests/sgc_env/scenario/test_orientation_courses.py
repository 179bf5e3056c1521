"""The memoised orientation courses that the three-rod bound and the env's tracks share."""

from __future__ import annotations

import numpy as np
import pytest

from sgc_env.envs.tracks import compile_tracks
from sgc_env.paper.orientation import goal_rotations, neighbour_paces, split_rotation
from sgc_env.scenario import Body, Goal, Scenario
from sgc_env.scenario.orientation_courses import orientation_courses
from sgc_env.scenes import random_scenario

TRACK_FIELDS = (
    "goal_ids", "ticks", "times", "targets", "points", "course_start", "durations", "next_start",
    "next_duration", "end_velocity", "via",
)  # fmt: skip


def _same_tracks(a, b) -> None:
    for x, y in zip(a, b, strict=True):
        for part in ("position", "orientation"):
            tx, ty = getattr(x, part), getattr(y, part)
            assert (tx is None) == (ty is None)
            for name in TRACK_FIELDS if tx is not None else ():
                u, v = getattr(tx, name), getattr(ty, name)
                assert u.dtype == v.dtype and u.shape == v.shape and u.tobytes() == v.tobytes()


def test_the_courses_are_the_orientation_functions_values():
    start = (0.0, 0.0, 0.0, 1.0)
    quarter = (0.0, 0.0, float(np.sin(np.pi / 4)), float(np.cos(np.pi / 4)))
    goals = ((quarter, None), (None, (0.0, 7.0, 0.0)), (start, None))
    times = (0.5, 1.5, 2.0)
    rest = (0.0, 0.0, 0.0)
    courses = orientation_courses(start, goals, times, rest, rest, 60)
    rotations = goal_rotations(start, goals)
    paces = neighbour_paces(rotations, times, rest, rest)
    assert courses.rotations == tuple(rotations) and courses.paces == tuple(paces)
    split = split_rotation(rotations[1], 0.5, 1.5, 60, rate_in=paces[1][0], rate_out=paces[1][1])
    assert courses.splits == (None, tuple(split), None) and len(split) > 3


def test_a_kept_rod_reuses_the_bounds_courses_and_compiles_the_same_tracks():
    orientation_courses.cache_clear()
    scenario = random_scenario(np.random.default_rng(11), "three_rods")
    misses = orientation_courses.cache_info().misses
    cached = compile_tracks(scenario)
    info = orientation_courses.cache_info()
    assert info.misses == misses and info.hits >= len(scenario.bodies)
    orientation_courses.cache_clear()
    _same_tracks(cached, compile_tracks(scenario))


def test_a_refused_split_names_the_goal():
    body = Body(
        name="spinner", shape="rod", size=(0.6, 0.03),
        goals=(Goal(orientation=(0.0, 0.0, 0.0, 1.0), time=0.5),
               Goal(relative_rotation=(0.0, 7.0, 0.0), time=0.5 + 2 / 60)),
    )  # fmt: skip
    scenario = Scenario(bodies=(body,), resolved=True)
    with pytest.raises(ValueError, match=r"spinner\.goals\[1\]: .* only 2 are left"):
        compile_tracks(scenario)
