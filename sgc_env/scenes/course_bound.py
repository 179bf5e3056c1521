"""Planner-free features of what a body's SGC plan demands, from its course data alone.

Why: the planner (``sgc_env.scenario.demand.demand_bounds``) costs ~60 ms per rod, so checking
every random three-rod draw with it made a reset cost ~170 ms. These features read only the goal
times, the tracked point's nails and the goal rotations (well under a millisecond per body).

With ``v_j`` the tracked point's average velocity over course ``j`` (chord / duration ``T_j``;
the start velocity before the first course, the end velocity after the last) and ``w_j`` the
orientation track's average angular velocity (rotation vector / ``T_j``; a somersault split
into the sub-courses the planner flies, :func:`~sgc_env.paper.orientation.split_rotation`)::

    point = max_j (|v_j - v_{j-1}| + |v_{j+1} - v_j|) / T_j       (an acceleration)
    spin  = max_j (|w_j - w_{j-1}| + |w_{j+1} - w_j|) / T_j + SPIN_RATE max(|w_{j-1..j+1}|)^2

A plan's peak force is then at most ``m (|g| + K_F (point + r spin))`` and its peak torque
``I_max K_S spin`` (``r``: the tracked point's offset from the centre of mass), as
``demand_bounds`` composes them, for factors ``K_F``, ``K_S`` a family measures on its draws
(``scripts/fit_course_bound.py``) and tests: the course shape behind them is the planner's, so
they are measured, not derived. One case has no such factor: an orientation course entered much
faster than its own pace (a near-straight stretch after a bend) makes the paper's exponential
course overshoot without limit (measured up to 1e31 rad/s^2), so a course entered at more
than ``PACE_JUMP`` times its own pace has no features (``None``).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from sgc_env.paper import quaternion as quat
from sgc_env.scenario.demand import inertia_diagonal
from sgc_env.scenario.model import Body

__all__ = [
    "PACE_JUMP", "CourseFeatures", "body_bound", "course_features", "demand_bound",
    "point_feature", "spin_feature",
]  # fmt: skip

PACE_JUMP = 6.0
"""Largest ``|w_{j-1}| / |w_j|`` with features (on 600 drawn rods the plan stayed bounded up
to 8; the first runaway course was entered at 12 times its pace)."""
SPIN_RATE = 1.5
"""Weight of the squared rate in ``spin`` (the planner's ``omega`` and ``omega'`` terms)."""

CourseFeatures = tuple[float, float]
"""``(point, spin)``: see the module docstring."""


def _vector(v: Sequence[float] | np.ndarray) -> tuple[float, float, float]:
    x, y, z = map(float, v)
    return x, y, z


def _changes(
    velocities: Sequence[Sequence[float]], before: Sequence[float], after: Sequence[float]
) -> list[float]:
    """``|v_j - v_{j-1}| + |v_{j+1} - v_j|`` per course (3-vectors). Plain floats: the same
    arithmetic as numpy's ``norm(diff(...), axis=1)`` (a sum of squares in axis order), several
    times cheaper on the ~20 rows of a course list (and a draw checks three or four)."""
    rows = [before, *velocities, after]
    steps = [
        math.sqrt((bx - ax) * (bx - ax) + (by - ay) * (by - ay) + (bz - az) * (bz - az))
        for (ax, ay, az), (bx, by, bz) in zip(rows[:-1], rows[1:], strict=True)
    ]
    return [a + b for a, b in zip(steps[:-1], steps[1:], strict=True)]


def _durations(times: Sequence[float]) -> list[float]:
    return [b - a for a, b in zip([0.0, *times[:-1]], times, strict=True)]


def _end(v: tuple[float, float, float] | None) -> np.ndarray:
    return np.zeros(3) if v is None else np.asarray(v, float)


def point_feature(
    times: Sequence[float],
    start: np.ndarray,
    nails: np.ndarray,
    velocity: np.ndarray,
    end_velocity: np.ndarray,
) -> float:
    """``point`` of a tracked point starting at ``start`` with ``velocity`` and passing
    ``nails`` (rows) at ``times``."""  # fmt: skip
    durations = _durations([float(t) for t in times])
    points = [_vector(start), *np.asarray(nails, float).tolist()]
    velocities = [
        ((bx - ax) / d, (by - ay) / d, (bz - az) / d)
        for (ax, ay, az), (bx, by, bz), d in zip(points[:-1], points[1:], durations, strict=True)
    ]
    changes = _changes(velocities, _vector(velocity), _vector(end_velocity))
    return max(c / d for c, d in zip(changes, durations, strict=True))


def _orientation_courses(
    start: Sequence[float],
    goals: Sequence[tuple[Sequence[float] | None, Sequence[float] | None]],
    times: Sequence[float],
    rates: tuple[np.ndarray, np.ndarray],
    frequency: int,
) -> tuple[list[tuple[float, ...]], list[float]]:
    """Rotation vector and duration of every course of the orientation track, split as the
    planner splits it (``goals``: ``(orientation, relative_rotation)`` each)."""  # fmt: skip
    # Loaded at the first draw: the orientation modules import scipy, and ``import sgc_env``
    # (which reads the families for the registry) stays without it.
    from sgc_env.paper.orientation import split_rotation
    from sgc_env.scenario.orientation_courses import orientation_courses

    # Memoised: the env's tracks of a kept rod ask for the same courses (a cache hit).
    courses = orientation_courses(
        _floats(start), tuple((_floats(q), _floats(r)) for q, r in goals),
        tuple(map(float, times)), _floats(rates[0]), _floats(rates[1]), frequency,
    )  # fmt: skip
    steps: list[tuple[float, ...]] = []
    ends: list[float] = []
    t_prev = 0.0
    for (_, relative), rotation, t, split, (rate_in, rate_out) in zip(
        goals, courses.rotations, times, courses.splits, courses.paces, strict=True
    ):
        if relative is None:
            steps.append(rotation)
            ends.append(t)
        else:
            if split is None:  # refused: the splitter's error
                split = tuple(split_rotation(
                    rotation, t_prev, t, frequency, rate_in=rate_in, rate_out=rate_out
                ))  # fmt: skip
            for step, end in split:
                steps.append(step)
                ends.append(end)
        t_prev = t
    return steps, _durations(ends)


def _floats(v: Sequence[float] | np.ndarray | None) -> tuple[float, ...] | None:
    """A hashable key part (the orientation functions read its entries as floats)."""
    if v is None or type(v) is tuple:  # the draws' quaternions and rotations already are
        return v
    return tuple(map(float, v))


def spin_feature(
    start: Sequence[float],
    goals: Sequence[tuple[Sequence[float] | None, Sequence[float] | None]],
    times: Sequence[float],
    rates: tuple[np.ndarray, np.ndarray],
    frequency: int,
) -> float | None:
    """``spin`` of an orientation track from ``start`` through ``goals``
    (``(orientation, relative_rotation)`` each) at ``times``, ``rates`` the initial and end
    angular velocities; None where a course is entered faster than ``PACE_JUMP`` times its own
    pace."""  # fmt: skip
    steps, durations = _orientation_courses(start, goals, times, rates, frequency)
    velocities = [(x / d, y / d, z / d) for (x, y, z), d in zip(steps, durations, strict=True)]
    speeds = [math.sqrt(x * x + y * y + z * z) for x, y, z in velocities]
    first, last = (float(np.linalg.norm(r)) for r in rates)
    for incoming, speed in zip([first, *speeds[:-1]], speeds, strict=True):
        if speed > 1e-9 and incoming > PACE_JUMP * speed:
            return None
    padded = [first, *speeds, last]
    changes = _changes(velocities, _vector(rates[0]), _vector(rates[1]))
    return max(
        c / d + SPIN_RATE * (f * f)
        for c, d, f in zip(
            changes, durations, map(max, padded[:-2], padded[1:-1], padded[2:]), strict=True
        )
    )


def course_features(b: Body, frequency: int) -> CourseFeatures | None:
    """``(point, spin)`` of a resolved body at ``frequency`` Hz, or None where an orientation
    course is entered faster than ``PACE_JUMP`` times its own pace."""
    rates = np.asarray(b.angular_velocity, float), _end(b.end_angular_velocity)
    if b.has_orientation_track:
        turns = [g for g in b.goals if g.has_orientation]
        spin = spin_feature(
            b.orientation, [(g.orientation, g.relative_rotation) for g in turns],
            [float(g.time) for g in turns], rates, frequency,  # type: ignore[arg-type]
        )  # fmt: skip
        if spin is None:
            return None
    else:
        spin = float(np.dot(rates[0], rates[0]))
    if not b.has_position_track:
        return 0.0, spin
    goals = [g for g in b.goals if g.has_position]
    start = np.asarray(b.position) + np.asarray(quat.rotate(b.orientation, goals[0].point))
    point = point_feature(
        [float(g.time) for g in goals], start, np.array([g.nail for g in goals], float),  # type: ignore[arg-type]
        np.asarray(b.linear_velocity, float), _end(b.end_velocity),
    )  # fmt: skip
    return point, spin


def demand_bound(
    features: CourseFeatures,
    factors: tuple[float, float],
    *,
    mass: float,
    inertia: float,
    arm: float,
    gravity: float,
) -> tuple[float, float]:
    """``(force, torque)`` bound of the plan's peaks from ``features`` and a family's measured
    ``factors`` ``(K_F, K_S)``: ``inertia`` the largest principal moment, ``arm`` the tracked
    point's distance from the centre of mass."""  # fmt: skip
    point, spin = features
    k_force, k_spin = factors
    return mass * (gravity + k_force * (point + arm * spin)), inertia * k_spin * spin


def body_bound(
    b: Body, features: CourseFeatures, factors: tuple[float, float], gravity: float
) -> tuple[float, float]:
    """:func:`demand_bound` with the body's mass, inertia and tracked point."""
    points = {g.point for g in b.goals if g.has_position}
    arm = max((float(np.linalg.norm(p)) for p in points), default=0.0)
    inertia = float(inertia_diagonal(b.shape, b.size, b.mass).max())
    return demand_bound(features, factors, mass=b.mass, inertia=inertia, arm=arm, gravity=gravity)
