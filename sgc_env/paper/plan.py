"""Initial state + goal sequence -> a continuous-time SGC plan for one rigid body.

Two tracks are planned per body (design.md): the orientation track on the world-frame
rotation vector ``phi`` (``R = Exp(phi) R_goal``) and the position track on the deviation of
the tracked body point ``p = x + R r`` from the nail (``r`` is the goal's point, body frame).
The orientation plan is made first; the position track then uses ``R(t)``, ``omega(t)`` and
``omega_dot(t)`` to turn point motion into centre-of-mass motion by the chain rule::

    x = p - R r,   x' = p' - omega x (R r),   x'' = p'' - omega_dot x (R r) - omega x (omega x R r)

Defined behaviours (see docs/core.md):

* each course starts from the state the previous one reaches, so position and velocity are
  continuous at every goal; the end velocity of a course follows ``frames.course_end_velocity``;
* when goal ``i+1`` tracks another body point, ``Delta_{i+1}(0)`` is measured with the new
  point at ``t_i``: ``nail_i - nail_{i+1} + R(t_i) (r_{i+1} - r_i)``;
* without an orientation track the body turns with its initial angular velocity,
  ``R(t) = Exp(omega_0 t) R_0``; without a position track the centre of mass moves with its
  initial velocity;
* after the last goal of a track the deviation moves on with the track's end velocity
  (constant linear velocity of the point / constant angular velocity);
* goal times need not fall on any control grid: the plan is continuous in time.
"""

from __future__ import annotations

import bisect
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any, cast

import numpy as np
from numpy.typing import ArrayLike
from scipy.spatial.transform import Rotation

from sgc_env.paper.end_rules import DEFAULT_END_RULE, END_RULES
from sgc_env.paper.frames import (
    C_HIGH,
    C_LOW,
    K_MIN,
    EndVelocity,
    FrameCourse,
    course_end_velocity,
)
from sgc_env.paper.frames import solve_course_in_frame as _solve_in_frame
from sgc_env.paper.orientation import (
    angular_acceleration,
    goal_rotations,
    left_jacobian,
    left_jacobian_inverse_apply,
    neighbour_paces,
    split_rotation,
)

__all__ = [
    "BodyPlan",
    "BodyState",
    "CourseDiagnostics",
    "OrientationGoal",
    "PlanOptions",
    "PlanSample",
    "PositionGoal",
    "plan_body",
]


def _vec(value: ArrayLike, size: int, where: str, name: str) -> np.ndarray:
    a = np.asarray(value, dtype=float)
    if a.shape != (size,):
        raise ValueError(f"{where}: {name} must have shape ({size},), got {a.shape}")
    if np.isnan(a).any():
        raise ValueError(f"{where}: {name} contains NaN")
    if not np.isfinite(a).all():
        raise ValueError(f"{where}: {name} contains inf")
    return a


def _quat(value: ArrayLike, where: str, name: str) -> Rotation:
    q = _vec(value, 4, where, name)
    if float(np.linalg.norm(q)) < 1e-12:
        raise ValueError(f"{where}: {name} quaternion has zero norm")
    return Rotation.from_quat(q)


@dataclass(frozen=True)
class BodyState:
    """Rigid-body state: centre of mass (world), quaternion ``(x, y, z, w)``, velocities."""

    position: np.ndarray
    orientation: np.ndarray
    linear_velocity: np.ndarray = field(default_factory=lambda: np.zeros(3))
    angular_velocity: np.ndarray = field(default_factory=lambda: np.zeros(3))


@dataclass(frozen=True)
class PositionGoal:
    """Point-to-nail goal: body point ``point`` (body frame) on ``nail`` (world) at ``time``."""

    time: float
    nail: np.ndarray
    point: np.ndarray = field(default_factory=lambda: np.zeros(3))


@dataclass(frozen=True)
class OrientationGoal:
    """Orientation goal at ``time``: exactly one of an absolute ``orientation`` (quaternion
    xyzw) or a ``relative_rotation`` (world rotation vector from the previous orientation
    goal, or from the initial orientation; may exceed pi: a somersault)."""

    time: float
    orientation: np.ndarray | None = None
    relative_rotation: np.ndarray | None = None


@dataclass(frozen=True)
class PlanOptions:
    """The k-rule constants of ``sgc_env.paper.frames`` (defaults documented there), the
    end-velocity rule of interior goals (``"tangent"``, the default, or ``"paper"``: eqs.
    12-14) and the control grid split somersaults are timed on."""

    c_low: float = C_LOW
    c_high: float = C_HIGH
    k_min: float = K_MIN
    end_rule: str = DEFAULT_END_RULE
    control_frequency: int | None = None
    """Time a split somersault's sub-courses on this control grid, as the env does (None:
    evenly in continuous time)."""

    def __post_init__(self) -> None:
        if self.control_frequency is not None and not self.control_frequency > 0:
            raise ValueError(
                f"options: control_frequency must be > 0, got {self.control_frequency!r}"
            )
        if not 0.8 < self.c_low:
            raise ValueError(f"options: c_low must be > 0.8 (paper eq. 12), got {self.c_low!r}")
        if not 0.0 < self.c_high < 1.0:
            raise ValueError(f"options: c_high must be in (0, 1) (eq. 13), got {self.c_high!r}")
        if not 0.0 < self.k_min <= 1.0:
            raise ValueError(f"options: k_min must be in (0, 1], got {self.k_min!r}")
        if self.end_rule not in END_RULES:
            raise ValueError(
                f"options: end_rule must be one of {list(END_RULES)}, got {self.end_rule!r}"
            )


@dataclass(frozen=True)
class CourseDiagnostics:
    """One planned course: which track, its goal index, times, branches and ``k`` per
    component of ``S_i`` (NaN for Hermite/dwell components), the turn to the next course and
    whether the paper's assumptions hold. ``rule`` is the end-velocity rule used."""

    track: str
    index: int
    t_start: float
    t_end: float
    branches: tuple[str, ...]
    k: np.ndarray
    turn_angle: float
    within_paper_assumption: bool
    rule: str


@dataclass(frozen=True)
class PlanSample:
    """Planned state at one time (world frame; quaternion xyzw)."""

    position: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray
    orientation: np.ndarray
    angular_velocity: np.ndarray
    angular_acceleration: np.ndarray
    point_position: np.ndarray
    point_velocity: np.ndarray


class _Track:
    """Courses of one track: deviation state at absolute time ``t``."""

    def __init__(
        self,
        starts: list[float],
        ends: list[float],
        courses: list[FrameCourse],
        end_velocity: np.ndarray,
    ) -> None:
        self.starts, self.ends, self.courses = starts, ends, courses
        self.end_velocity = end_velocity

    def locate(self, t: float) -> int:
        """Index of the course with ``t_start < t <= t_end`` (first course for ``t <= 0``);
        ``len(courses)`` after the last goal."""
        return bisect.bisect_left(self.ends, t)

    def state(self, t: float) -> tuple[int, np.ndarray, np.ndarray, np.ndarray]:
        i = self.locate(t)
        if i == len(self.courses):
            ve = self.end_velocity
            return i, ve * (t - self.ends[-1]), ve.copy(), np.zeros(3)
        d, v, a = self.courses[i].state(t - self.starts[i])
        return i, d, v, a


class BodyPlan:
    """Result of :func:`plan_body`. ``sample(t)`` for ``t >= 0``; ``courses`` diagnostics."""

    def __init__(
        self,
        initial: tuple[np.ndarray, Rotation, np.ndarray, np.ndarray],
        orient_goals: list[Rotation],
        goal_rotations: list[Rotation],
        orient_track: _Track | None,
        pos_goals: list[tuple[np.ndarray, np.ndarray]],
        pos_track: _Track | None,
        courses: list[CourseDiagnostics],
    ) -> None:
        self._x0 = initial[0]
        self._r0 = initial[1]
        self._v0 = initial[2]
        self._w0 = initial[3]
        self._orient_goals = orient_goals  # Rotation at the end of each orientation course
        self._goal_rotations = goal_rotations  # one per orientation goal (not per piece)
        self._orient = orient_track
        self._pos_goals = pos_goals  # list of (nail, point)
        self._pos = pos_track
        self.courses: list[CourseDiagnostics] = courses

    def goal_orientations(self) -> list[np.ndarray]:
        """Resolved goal orientations (quaternions xyzw), relative goals composed."""
        return [r.as_quat() for r in self._goal_rotations]

    def _orientation(self, t: float) -> tuple[Rotation, np.ndarray, np.ndarray]:
        if self._orient is None:
            return Rotation.from_rotvec(self._w0 * t) * self._r0, self._w0, np.zeros(3)
        i, phi, phi_dot, phi_ddot = self._orient.state(t)
        goal = self._orient_goals[min(i, len(self._orient_goals) - 1)]
        rot = Rotation.from_rotvec(phi) * goal
        if i == len(self._orient_goals):
            return rot, phi_dot, np.zeros(3)
        omega = left_jacobian(phi) @ phi_dot
        return rot, omega, angular_acceleration(phi, phi_dot, phi_ddot)

    def deviations(
        self, t: np.ndarray, track: str = "position"
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Planned ``(D, D', D'')`` of one track at an array of times, each ``t.shape + (3,)``:
        the tracked point's deviation from its nail (``"position"``, world frame) or ``phi``
        (``"orientation"``). One vectorised evaluation per course, where ``sample`` costs
        about 0.5 ms a call: what a feasibility check on every reset can afford. A course owns
        ``(t_start, t_end]``; after the track's last goal the deviation moves on with the
        track's end velocity; zeros for a body without that track.
        """
        if track not in ("position", "orientation"):
            raise ValueError(f"track must be 'position' or 'orientation', got {track!r}")
        tr = self._pos if track == "position" else self._orient
        t = np.asarray(t, float)
        d, v, a = (np.zeros(t.shape + (3,)) for _ in range(3))
        if tr is None:
            return d, v, a
        index = np.searchsorted(tr.ends, t, side="left")
        for i, course in enumerate(tr.courses):
            mask = index == i
            if mask.any():
                d[mask], v[mask], a[mask] = course.evaluate(t[mask] - tr.starts[i])
        after = index == len(tr.courses)
        v[after] = tr.end_velocity
        d[after] = np.multiply.outer(t[after] - tr.ends[-1], tr.end_velocity)
        return d, v, a

    def sample(self, t: float) -> PlanSample:
        """Planned state at absolute time ``t`` (seconds, ``t >= 0``)."""
        t = float(t)
        if not (math.isfinite(t) and t >= 0.0):
            raise ValueError(f"t must be finite and >= 0, got {t!r}")
        rot, omega, omega_dot = self._orientation(t)
        if self._pos is None:
            x = self._x0 + self._v0 * t
            return PlanSample(
                x, self._v0.copy(), np.zeros(3), rot.as_quat(), omega, omega_dot, x, self._v0.copy()
            )
        i, d, dv, da = self._pos.state(t)
        nail, point = self._pos_goals[min(i, len(self._pos_goals) - 1)]
        rr = rot.apply(point)
        p = nail + d
        w_rr = np.cross(omega, rr)
        x = p - rr
        v = dv - w_rr
        a = da - np.cross(omega_dot, rr) - np.cross(omega, w_rr)
        return PlanSample(x, v, a, rot.as_quat(), omega, omega_dot, p, dv)


def _check_times(times: Sequence[float], kind: str) -> list[float]:
    out, prev = [], 0.0
    for i, t in enumerate(times):
        where = f"{kind} goal {i}"
        try:
            t = float(t)
        except (TypeError, ValueError):
            raise ValueError(f"{where}: time must be a number, got {t!r}") from None
        if not math.isfinite(t):
            raise ValueError(f"{where}: time must be finite, got {t!r}")
        if t <= prev:
            what = "the plan start t = 0" if i == 0 else f"goal {i - 1} at t = {prev!r}"
            raise ValueError(
                f"{where}: time {t!r} is not after {what}; goal times must increase "
                "(a course needs a positive duration)"
            )
        out.append(t)
        prev = t
    return out


def _orientation_courses(
    r0: Rotation,
    goals: Sequence[OrientationGoal],
    times: Sequence[float],
    control_frequency: int | None = None,
    rates: tuple[np.ndarray, np.ndarray | None] = (np.zeros(3), None),
) -> tuple[list[tuple[Rotation, np.ndarray, float, int]], list[Rotation]]:
    """(goal rotation, phi at the course start, end time, goal index) per course, and the
    rotation each goal reaches.

    A relative rotation longer than ``MAX_COURSE_ROTATION`` becomes equal sub-rotations about
    its axis (:func:`~sgc_env.paper.orientation.split_rotation`, the env's splitter): a course
    starting on ``|phi| = 2 pi`` could not carry the angular velocity across its axis. With a
    ``control_frequency`` the sub-courses end on the env's ticks. ``rates``: the initial and
    the end angular velocity, which set the paces of a smooth split
    (:func:`~sgc_env.paper.orientation.neighbour_paces`, as the env).
    """
    out, reached = [], []
    prev, t_prev = r0, 0.0
    checked: list[tuple[np.ndarray | None, np.ndarray | None]] = []
    for i, g in enumerate(goals):
        where = f"orientation goal {i}"
        if (g.orientation is None) == (g.relative_rotation is None):
            raise ValueError(f"{where}: give exactly one of orientation and relative_rotation")
        if g.relative_rotation is None:
            quat = _quat(cast(np.ndarray, g.orientation), where, "orientation").as_quat()
            checked.append((quat, None))
        else:
            checked.append((None, _vec(g.relative_rotation, 3, where, "relative_rotation")))
    paces = neighbour_paces(goal_rotations(r0.as_quat(), checked), times, rates[0], rates[1])
    for i, g in enumerate(goals):
        where = f"orientation goal {i}"
        if (g.orientation is None) == (g.relative_rotation is None):
            raise ValueError(f"{where}: give exactly one of orientation and relative_rotation")
        if g.relative_rotation is None:
            goal = _quat(cast(np.ndarray, g.orientation), where, "orientation")  # checked above
            out.append((goal, (prev * goal.inv()).as_rotvec(), times[i], i))
            prev = goal
        else:
            rel = _vec(g.relative_rotation, 3, where, "relative_rotation")
            rate_in, rate_out = paces[i]
            for step, end in split_rotation(
                rel, t_prev, times[i], control_frequency, where, rate_in=rate_in, rate_out=rate_out
            ):
                prev = Rotation.from_rotvec(step) * prev
                out.append((prev, -np.array(step), end, i))
        reached.append(prev)
        t_prev = times[i]
    return out, reached


def _plan_orientation(
    r0: Rotation,
    w0: np.ndarray,
    goals: Sequence[OrientationGoal],
    times: Sequence[float],
    end_w: np.ndarray | None,
    opts: PlanOptions,
    diags: list[CourseDiagnostics],
) -> tuple[list[Rotation], list[Rotation], _Track]:
    pieces, reached = _orientation_courses(r0, goals, times, opts.control_frequency, (w0, end_w))
    starts = [phi0 for _, phi0, _, _ in pieces]
    ends = [end for _, _, end, _ in pieces]
    courses: list[Any] = []
    t_prev = 0.0
    phi_dot: np.ndarray = np.array(left_jacobian_inverse_apply(starts[0], w0))
    for i, phi0 in enumerate(starts):
        T = ends[i] - t_prev
        last = i == len(starts) - 1
        nxt = None if last else starts[i + 1]
        v_end, info = course_end_velocity(
            phi0, nxt, T, None if last else ends[i + 1] - ends[i],
            end_velocity=end_w if last else None,
            c_low=opts.c_low, c_high=opts.c_high, k_min=opts.k_min, rule=opts.end_rule,
        )  # fmt: skip
        course = _solve_in_frame(info.frame, phi0, phi_dot, T, v_end)
        courses.append(course)
        diags.append(_diag("orientation", pieces[i][3], t_prev, ends[i], course, info))
        if not last:
            # omega at phi = 0 is v_end
            phi_dot = np.array(left_jacobian_inverse_apply(starts[i + 1], v_end))
        t_prev = ends[i]
    end_state = courses[-1].state(courses[-1].duration)[1]
    track = _Track([0.0, *ends[:-1]], ends, courses, end_state)
    return [goal for goal, _, _, _ in pieces], reached, track


def _diag(
    track: str, i: int, t0: float, t1: float, course: FrameCourse, info: EndVelocity
) -> CourseDiagnostics:
    return CourseDiagnostics(
        track,
        i,
        t0,
        t1,
        course.branches,
        course.k,
        info.turn_angle,
        info.within_paper_assumption,
        info.rule,
    )


def _plan_position(
    x0: np.ndarray,
    v0: np.ndarray,
    orientation_at: Callable[[float], tuple[Rotation, np.ndarray, np.ndarray]],
    goals: Sequence[PositionGoal],
    times: Sequence[float],
    end_v: np.ndarray | None,
    opts: PlanOptions,
    diags: list[CourseDiagnostics],
) -> tuple[list[tuple[np.ndarray, np.ndarray]], _Track]:
    resolved = []
    for i, g in enumerate(goals):
        where = f"position goal {i}"
        resolved.append((_vec(g.nail, 3, where, "nail"), _vec(g.point, 3, where, "point")))
    rot, omega, _ = orientation_at(0.0)
    nail, point = resolved[0]
    rr = rot.apply(point)
    d0 = x0 + rr - nail
    dv0 = v0 + np.cross(omega, rr)
    courses, t_prev = [], 0.0
    for i in range(len(resolved)):
        T = times[i] - t_prev
        last = i == len(resolved) - 1
        nail, point = resolved[i]
        if last:
            nxt, offset_world, omega_i = None, np.zeros(3), np.zeros(3)
        else:
            rot_i, omega_i, _ = orientation_at(times[i])
            offset_world = rot_i.apply(resolved[i + 1][1] - point)
            nxt = nail - resolved[i + 1][0] + offset_world
        v_end, info = course_end_velocity(
            d0,
            nxt,
            T,
            None if last else times[i + 1] - times[i],
            end_velocity=end_v if last else None,
            c_low=opts.c_low,
            c_high=opts.c_high,
            k_min=opts.k_min,
            rule=opts.end_rule,
        )
        course = _solve_in_frame(info.frame, d0, dv0, T, v_end)
        courses.append(course)
        diags.append(_diag("position", i, t_prev, times[i], course, info))
        if not last:
            d0 = nxt
            dv0 = v_end + np.cross(omega_i, offset_world)
        t_prev = times[i]
    end = courses[-1].state(courses[-1].duration)[1]
    return resolved, _Track([0.0, *times[:-1]], list(times), courses, end)


def plan_body(
    initial: BodyState,
    position_goals: Sequence[PositionGoal],
    orientation_goals: Sequence[OrientationGoal] = (),
    *,
    end_velocity: ArrayLike | None = None,
    end_angular_velocity: ArrayLike | None = None,
    options: PlanOptions | None = None,
) -> BodyPlan:
    """Plan one body through its goals (absolute times, the initial state is at ``t = 0``).

    ``end_velocity`` is the tracked point's velocity at the last position goal and
    ``end_angular_velocity`` the angular velocity at the last orientation goal; None means the
    last course's average velocity (``k = 1``), zeros mean arrive at rest. Raises ValueError
    naming the offending goal and field for bad input.
    """
    opts = options or PlanOptions()
    where = "initial state"
    x0 = _vec(initial.position, 3, where, "position")
    r0 = _quat(initial.orientation, where, "orientation")
    v0 = _vec(initial.linear_velocity, 3, where, "linear_velocity")
    w0 = _vec(initial.angular_velocity, 3, where, "angular_velocity")
    position_goals, orientation_goals = list(position_goals), list(orientation_goals)
    if not position_goals and not orientation_goals:
        raise ValueError("no goals: position_goals and orientation_goals are both empty")
    end_v = None if end_velocity is None else _vec(end_velocity, 3, "plan", "end_velocity")
    end_w = (
        None
        if end_angular_velocity is None
        else _vec(end_angular_velocity, 3, "plan", "end_angular_velocity")
    )
    p_times = _check_times([g.time for g in position_goals], "position")
    o_times = _check_times([g.time for g in orientation_goals], "orientation")
    diags: list[CourseDiagnostics] = []
    rots: list[Rotation] = []
    goal_rots: list[Rotation] = []
    o_track = None
    if orientation_goals:
        rots, goal_rots, o_track = _plan_orientation(
            r0, w0, orientation_goals, o_times, end_w, opts, diags
        )
    plan = BodyPlan((x0, r0, v0, w0), rots, goal_rots, o_track, [], None, diags)
    if position_goals:
        resolved, p_track = _plan_position(
            x0, v0, plan._orientation, position_goals, p_times, end_v, opts, diags
        )
        plan = BodyPlan((x0, r0, v0, w0), rots, goal_rots, o_track, resolved, p_track, diags)
    return plan
