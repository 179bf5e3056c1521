"""The ``"smooth"`` rule's transient sub-goals on a minimum-jerk reference (issue 23).

An SGC course solves its behaviour equation from position and velocity only, so its
acceleration jumps at every goal, and on a long course through a change of pace its own jerk
is several times a spline's (docs/smoothness.md). The smooth rule therefore gives the expert
*transient sub-goals*: per body and track it builds the C4 minimum-jerk reference through the
track's real goals at their times (:mod:`baselines.controllers.minimum_jerk`, the law of the
``minimum-jerk`` baseline), samples it at control ticks, and every sub-course between two
sub-goals is an ordinary SGC course that starts and ends on the reference with the
reference's velocity. The env, its goals and its schedule are untouched: sub-goals live in
the expert only, and every real goal is still the last sub-goal of its course (met exactly).

How far apart the sub-goals are is chosen, not fixed: going back from the track's last goal,
each sub-course is the longest of at most :data:`LONGEST_SUBCOURSE` ticks whose SGC course
keeps its acceleration (at its start, middle tick and end) within :data:`TOLERANCE` times the
reference's largest one-tick change of acceleration (its planned kink) of the reference's,
and over which the reference's velocity changes by at most :data:`BEND` of its average.
Where the reference moves fast and straight that is the longest; near a stop or a sharp
change of pace, where an SGC course through a few ticks bends away from the spline, it can be
one tick (then the course is the reference's next sample). One tick's change of acceleration
along the expert's plan is then about the reference's plus at most twice the tolerance.

The expert (:class:`baselines.controllers.expert.SGCExpert`, ``end_rule="smooth"``) re-solves the
current sub-course every tick from the measured deviation from its sub-goal and the sub-course's
planned rate (:meth:`SubGoals.planned_rate`), and lands every tick's rotation by the exact
Newton step; docs/smoothness.md has the measurements behind both choices.

The table is keyed like the matched rule's (:mod:`baselines.controllers.matched_table`): body, track
and the course's float32 observation entries, so a stateless expert finds its course from any
state of the episode; courses of another scenario are not found.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import cast

import numpy as np

from baselines.controllers.matched_table import course_key, course_row
from baselines.controllers.minimum_jerk import MinimumJerkPath, MinimumJerkRotation
from sgc_env.envs.tracks import Track, compile_tracks
from sgc_env.paper import quaternion as quat
from sgc_env.paper.frames import Profile, Rows, Vec3, _component_profiles, _frame_rows, _mul, _mul_t
from sgc_env.paper.orientation import _coefficients, left_jacobian_inverse_apply
from sgc_env.scenario import Body, Scenario

__all__ = ["LONGEST_SUBCOURSE", "TOLERANCE", "SmoothCourse", "SubGoals", "smooth_table"]

LONGEST_SUBCOURSE = 8
"""Most control ticks between two sub-goals."""

TOLERANCE = 0.25
"""Largest gap between a sub-course's and the reference's acceleration, as a fraction of the
reference's planned kink on that track."""

BEND = 0.5
"""Largest change of the reference's velocity over a sub-course, as a fraction of its average
velocity: beyond it the course bends too much for an SGC course re-solved from a measured
state mid-way (measured on SGCThreeRodsRandom-v3 seed 10000's second rod, a turn at about
1.2 rad/s reversing within 8 ticks: 61.8 rad/s² of kink, 4.3x minimum jerk's, without this
limit; 13.2 with it)."""

_NO_COURSE = cast(tuple[Profile, Profile, Profile], ())
_IDENTITY: Rows = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))


@dataclass(frozen=True)
class SubGoals:
    """One track's sub-goals: control ticks (sorted; every real goal's tick among them), and
    per sub-goal the reference's point (or quaternion), its world velocity (angular velocity)
    there and the frame ``S`` of the sub-course that ends on it."""

    ticks: tuple[int, ...]
    values: tuple[tuple[float, ...], ...]
    velocities: tuple[Vec3, ...]
    rows: tuple[Rows, ...]
    orientation: bool
    courses: tuple[tuple[Profile, Profile, Profile], ...] = ()
    """Each sub-course's SGC course in its frame, solved from the reference at its start."""

    def planned_rate(self, j: int, tick: float, dt: float) -> Vec3:
        """The planned ``D'`` (``phi'``) of sub-course ``j`` at control tick ``tick``."""
        start = self.ticks[j - 1] if j > 0 else 0
        s0, s1, s2 = (p.state((tick - start) * dt) for p in self.courses[j])
        return _mul_t(self.rows[j], (s0[1], s1[1], s2[1]))


@dataclass(frozen=True)
class SmoothCourse:
    """What the expert needs about one observed course: its track's sub-goals, the tick its
    course ends on, its target (nail or goal quaternion) and whether that is a real goal
    (False for a split somersault's inner piece, which the reference need not pass)."""

    subgoals: SubGoals
    end_tick: int
    target: tuple[float, ...]
    real: bool


SmoothTable = dict[tuple[int, str, tuple[float, ...]], SmoothCourse]


def _cross(a: Vec3, b: Vec3) -> Vec3:
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _world_rates(phi: Vec3, phi_dot: Vec3, phi_ddot: Vec3) -> tuple[Vec3, Vec3]:
    """``omega = J_l phi'`` and ``omega' = J_l phi'' + (d/dt J_l) phi'`` in plain floats
    (:func:`~sgc_env.paper.orientation.angular_acceleration`, without numpy's per-call cost)."""
    a, b, da, db = _coefficients(math.hypot(*phi))
    dot = phi[0] * phi_dot[0] + phi[1] * phi_dot[1] + phi[2] * phi_dot[2]
    c1 = _cross(phi, phi_dot)
    cc1 = _cross(phi, c1)
    k2 = _cross(phi, phi_ddot)
    kk2 = _cross(phi, k2)
    dc = _cross(phi_dot, c1)
    omega = tuple(phi_dot[i] + a * c1[i] + b * cc1[i] for i in range(3))
    omega_dot = tuple(
        phi_ddot[i] + a * k2[i] + b * kk2[i] + da * dot * c1[i] + db * dot * cc1[i] + b * dc[i]
        for i in range(3)
    )
    return cast(Vec3, omega), cast(Vec3, omega_dot)


class _Reference:
    """Reference samples at every control tick of a track: value, world rate, acceleration."""

    def __init__(self, track: Track, body: Body, orientation: bool, freq: int) -> None:
        real = ~track.via if orientation and track.via.size else np.ones(track.size, bool)
        times = np.concatenate(([0.0], track.times[real]))
        self.ticks = np.arange(int(track.ticks[-1]) + 1)
        t = self.ticks / freq
        omega0 = np.asarray(body.angular_velocity, float)
        self.orientation = orientation
        if orientation:
            steps = -np.asarray(track.course_start)  # each piece's world rotation vector
            goal_of = np.cumsum(np.concatenate(([0], real[:-1].astype(int))))
            rotations = [steps[goal_of == g].sum(axis=0) for g in range(int(real.sum()))]
            quats = np.vstack([np.asarray(body.orientation, float), track.targets[real]])
            ref = MinimumJerkRotation(times, quats, omega0, rotations, body.end_angular_velocity)
            phi = ref.phi_path.position(t)
            rate = ref.phi_path.velocity(t)
            acc = ref.phi_path.acceleration(t)
            self.values = [tuple(q) for q in ref.orientation(t).tolist()]
            world = [
                _world_rates(*x)
                for x in zip(phi.tolist(), rate.tolist(), acc.tolist(), strict=True)
            ]
            self.rates = np.array([w for w, _ in world])
            self.accelerations = np.array([a for _, a in world])
        else:
            arm = quat.rotate(body.orientation, track.points[0])
            start = np.add(body.position, arm)
            v0 = np.asarray(body.linear_velocity, float) + np.cross(omega0, arm)
            points = np.vstack([start, track.targets])
            path = MinimumJerkPath(times, points, v0, end_velocity=body.end_velocity)
            self.values = [tuple(p) for p in path.position(t).tolist()]
            self.rates = path.velocity(t)
            self.accelerations = path.acceleration(t)
        self.kink = float(np.max(np.linalg.norm(np.diff(self.accelerations, axis=0), axis=1)))

    def deviation(self, a: int, b: int) -> Vec3:
        """Where tick ``a``'s reference is seen from sub-goal ``b``: ``D`` or ``phi``."""
        va, vb = self.values[a], self.values[b]
        if self.orientation:
            return quat.log(quat.mul_conjugate(va, vb))
        return (va[0] - vb[0], va[1] - vb[1], va[2] - vb[2])

    def rate(self, tick: int) -> Vec3:
        r = self.rates[tick]
        return (float(r[0]), float(r[1]), float(r[2]))


def _gap(
    ref: _Reference, a: int, b: int, c: int | None, dt: float
) -> tuple[float, Rows, tuple[Profile, Profile, Profile]]:
    """Largest gap between the SGC sub-course ``a -> b`` and the reference's acceleration
    (at ticks ``a``, the middle and ``b``), the sub-course's frame and its course."""
    d0 = ref.deviation(a, b)
    bend = math.dist(ref.rates[a], ref.rates[b]) * (b - a) * dt
    if b - a > 1 and bend > BEND * math.hypot(*d0):
        return math.inf, _IDENTITY, _NO_COURSE
    out = _frame_rows(d0, None if c is None else ref.deviation(b, c))
    rows = _IDENTITY if out is None else out[0]
    v0 = ref.rate(a)
    if ref.orientation:
        v0 = left_jacobian_inverse_apply(d0, v0)
    profiles = _component_profiles(
        _mul(rows, d0), _mul(rows, v0), _mul(rows, ref.rate(b)), (b - a) * dt
    )
    gap = 0.0
    for tick in sorted({a, (a + b) // 2, b}):
        s = [p.state((tick - a) * dt) for p in profiles]
        acc = _mul_t(rows, (s[0][2], s[1][2], s[2][2]))
        if ref.orientation:
            d = _mul_t(rows, (s[0][0], s[1][0], s[2][0]))
            v = _mul_t(rows, (s[0][1], s[1][1], s[2][1]))
            acc = _world_rates(d, v, acc)[1]
        gap = max(gap, math.dist(acc, ref.accelerations[tick]))
    return gap, rows, profiles


def _subgoals(ref: _Reference, goal_ticks: np.ndarray, dt: float) -> SubGoals:
    """Sub-goals back from the last goal: each sub-course the longest that stays within the
    tolerance (module docstring); every goal tick is a sub-goal."""
    tol = TOLERANCE * ref.kink
    goals = sorted({int(g) for g in goal_ticks})
    knots, rows, courses = [goals[-1]], [], []
    c: int | None = None
    b = goals[-1]
    while b > 0:
        floor = max([g for g in goals if g < b], default=0)
        for n in range(min(LONGEST_SUBCOURSE, b - floor), 0, -1):
            gap, frame, course = _gap(ref, b - n, b, c, dt)
            if gap <= tol or n == 1:
                break
        rows.append(frame)
        courses.append(course)
        c, b = b, b - n
        knots.append(b)
    knots.pop()  # tick 0 is the start, not a sub-goal
    knots.reverse()
    rows.reverse()
    courses.reverse()
    return SubGoals(
        tuple(knots), tuple(ref.values[k] for k in knots), tuple(ref.rate(k) for k in knots),
        tuple(rows), ref.orientation, tuple(courses),
    )  # fmt: skip


def smooth_table(scenario: Scenario) -> SmoothTable:
    """(body, ``"position"`` or ``"orientation"``, course key) -> :class:`SmoothCourse`, for
    every course of every track of a resolved scenario."""
    table: SmoothTable = {}
    freq = scenario.control_frequency
    for index, (body, tracks) in enumerate(
        zip(scenario.bodies, compile_tracks(scenario), strict=True)
    ):
        for name, track in (("position", tracks.position), ("orientation", tracks.orientation)):
            if track is None:
                continue
            orientation = name == "orientation"
            ref = _Reference(track, body, orientation, freq)
            real_goals = ~track.via if orientation and track.via.size else slice(None)
            subgoals = _subgoals(ref, track.ticks[real_goals], 1.0 / freq)
            for k in range(track.size):
                real = not (orientation and track.via.size and track.via[k])
                target = tuple(float(x) for x in track.targets[k])
                entry = SmoothCourse(subgoals, int(track.ticks[k]), target, real)
                table[(index, name, course_key(course_row(track, k)))] = entry
    return table
