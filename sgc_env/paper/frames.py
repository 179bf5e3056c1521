"""The normalized frame S_i of a course and the choice of the end velocity (eqs. 10-14).

In ``S_i`` the course's initial deviation is ``|D_i(0)|/sqrt3 (1, 1, 1)`` (all components
equal and positive) and the next course's initial deviation ``Delta_{i+1}(0)`` lies in the
plane of ``(1, 1, 1)`` and ``(1, 0, 0)`` on the ``(1, 0, 0)`` side. Per component
``rho_j = (Delta_j / t_{i+1}) / (D_j / t_i)`` and

* ``0 < rho < 1``: ``k = c_low * rho`` (paper eq. 12: ``c > 0.8``, ``k < 1``);
* ``rho >= 1``: ``k = max(1, c_high * rho)`` (eq. 13: ``c < 1``, ``k >= 1``);
* ``rho <= 0`` (turns sharper than ``atan(sqrt2)``, outside the paper):
  ``k = k_min * min(1, |Delta|/t_{i+1} / (|D|/t_i))``, i.e. ``k_min`` times the ratio of the
  two average speeds when the next course is the slower one (else a tiny next course would
  start with an unrepresentably fast approach).

The end velocity of course ``i`` is ``-k_j D_j / t_i`` per component of ``S_i``.

Defaults. ``c_low = 0.9``: inside the paper's range (0.8, 1); with ``c_low < 1`` a straight
continuation arrives slower than the next course's average speed, which is eq. 14 (the
next course then starts with ``gamma T > -1``). ``c_high = 0.95``: close to 1 so the transition
speed is near the faster of the two averages, without reaching it. ``k_min = 0.25``: on sharp
turns the component arrives at a quarter of the slower average speed instead of turning back.
Eq. 14 itself needs the frame ``S_{i+1}``, which depends on the goal after next; the solver
is total (it covers ``gamma T <= -1``), so eq. 14 is reported (:func:`condition_14`), not
enforced.

Beyond the paper: the tangent rule (``rule="tangent"``). The paper's k rules set each
component's end speed from its own ``rho``, so every goal gets a speed pulse. The tangent rule
instead gives an interior goal the end velocity of a smooth path through the neighbouring
nails: direction ``nail_{i+1} - nail_{i-1}`` (``= -(D_i(0) + Delta_{i+1}(0))``; for the first
course the start point stands for ``nail_{i-1}``), speed the mean of the two courses' average
speeds ``|D_i(0)|/t_i`` and ``|Delta_{i+1}(0)|/t_{i+1}`` (:func:`tangent_speed`). It is
realised per component of ``S_i`` through ``k_j = -v_j t_i / D_j(0)``, so the course is still
an SGC course: exact and punctual. Where it cannot be realised it falls back to the paper's
rule for that goal (``rule`` reported ``"sgc"``):

* a sign change in ``S_i``: some ``k_j < k_min`` (the tangent leaves the cone of directions that
  approach the nail in every component, or nearly so: a component would arrive at less than
  ``k_min`` of its average speed or move away from the nail);
* a hairpin (the next nail is the previous one): the chord has no direction.

The paper's pi/6 assumption is what bounds ``rho`` for eqs. 12-13; the tangent rule does not
use ``rho``, and its cone of realisable directions is wider: between two courses of equal
speed it is realised up to a turn of about 86 degrees (every component of ``S_i`` keeps at
least ``k_min`` of its average), where the paper's own rule already needs its ``rho <= 0``
extension beyond 54.7 degrees. So a turn beyond pi/6 alone does not make it fall back
(``within_paper_assumption`` still reports it): falling back there too measured SGCRod-v1's
whole-track SPARC back at the paper's (-2.42 against -2.22, seeds 10000-10009).

A change of pace is graded: the mean is clamped to between ``1 / PACE_STEP`` and
:data:`PACE_STEP` (2) times the course's own average speed, so no course ends faster than
twice, or slower than half, its average (``k`` within ``[0.5, 2]`` along the chord). A large
change of pace is then spread over the next courses instead of one course's exponential
end (an earlier rule switched to the next course's average beyond a ratio of 3: ``k`` near 15
on the three-rod scenes, 255 rad/s^2 at a goal). Measured with ``scripts/kink_table.py``
(three-rod scene and 10 held-out random rod scenes, 33 rods): the largest one-tick change of
acceleration over minimum jerk's, worst rod, linear 3.77 -> 2.97 and angular 79.9 -> 17.0
(docs/smoothness.md). A split somersault's pace change is graded by the split itself
(:func:`sgc_env.paper.orientation.split_rotation`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any, NamedTuple, cast

import numpy as np

from sgc_env.paper.course import CourseProfile, HermiteProfile, HoldProfile
from sgc_env.paper.end_rules import END_RULES
from sgc_env.paper.hermite import RestQuarticProfile

Vec3 = tuple[float, float, float]
Rows = tuple[Vec3, Vec3, Vec3]
"""A frame ``S_i`` as three row tuples (world unit vectors)."""
Vector = Sequence[float] | np.ndarray
"""A 3-vector as any sequence of floats or an array."""
Profile = CourseProfile | HermiteProfile | HoldProfile | RestQuarticProfile

__all__ = [
    "C_HIGH",
    "C_LOW",
    "END_RULES",
    "K_MIN",
    "PACE_STEP",
    "PAPER_MAX_TURN",
    "EndVelocity",
    "FrameCourse",
    "choose_k",
    "condition_14",
    "course_end_velocity",
    "next_deviation",
    "normalized_frame",
    "solve_course_in_frame",
    "tangent_speed",
    "turn_angle",
]

C_LOW = 0.9
C_HIGH = 0.95
K_MIN = 0.25
PAPER_MAX_TURN = math.pi / 6.0
PACE_STEP = 2.0
"""Largest ratio, either way, of a course's tangent-rule end speed to its own average speed."""
_SQ3 = 1.0 / math.sqrt(3.0)
_SQ6 = 1.0 / math.sqrt(6.0)
_SQ2 = 1.0 / math.sqrt(2.0)


def _vec3(x: Vector, name: str) -> Vec3:
    """Three Python floats (the hot path avoids numpy on 3-vectors); validates finiteness."""
    try:
        a0, a1, a2 = (x.tolist() if isinstance(x, np.ndarray) else x)
        a0, a1, a2 = float(a0), float(a1), float(a2)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a 3-vector, got {x!r}") from None
    if not (math.isfinite(a0) and math.isfinite(a1) and math.isfinite(a2)):
        raise ValueError(f"{name} contains NaN or inf: {x!r}")
    return a0, a1, a2


def _frame_rows(d: Vec3, nxt: Vec3 | None) -> tuple[Rows, float] | None:
    """Rows of ``S_i`` (world unit vectors) from Python-float 3-tuples; None if ``d`` is 0."""
    d0, d1, d2 = d
    norm = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
    if norm == 0.0:
        return None
    u0, u1, u2 = d0 / norm, d1 / norm, d2 / norm
    e = None
    if nxt is not None:
        n0, n1, n2 = nxt
        along = n0 * u0 + n1 * u1 + n2 * u2
        p0, p1, p2 = n0 - along * u0, n1 - along * u1, n2 - along * u2
        pn = math.sqrt(p0 * p0 + p1 * p1 + p2 * p2)
        if pn > 1e-12 * math.sqrt(n0 * n0 + n1 * n1 + n2 * n2):
            p0, p1, p2 = p0 / pn, p1 / pn, p2 / pn
            along = p0 * u0 + p1 * u1 + p2 * u2  # second Gram-Schmidt pass: nearly parallel
            p0, p1, p2 = p0 - along * u0, p1 - along * u1, p2 - along * u2
            pn = math.sqrt(p0 * p0 + p1 * p1 + p2 * p2)
            e = (p0 / pn, p1 / pn, p2 / pn)
    if e is None:  # deterministic roll: cross with the world axis least aligned with d
        a = (abs(u0), abs(u1), abs(u2))
        j = a.index(min(a))
        ax = [0.0, 0.0, 0.0]
        ax[j] = 1.0
        c0 = u1 * ax[2] - u2 * ax[1]
        c1 = u2 * ax[0] - u0 * ax[2]
        c2 = u0 * ax[1] - u1 * ax[0]
        cn = math.sqrt(c0 * c0 + c1 * c1 + c2 * c2)
        e = (c0 / cn, c1 / cn, c2 / cn)
    e0, e1, e2 = e
    f0, f1, f2 = u1 * e2 - u2 * e1, u2 * e0 - u0 * e2, u0 * e1 - u1 * e0
    # row j = N[j,0] d_hat + N[j,1] e + N[j,2] f with N's columns (1,1,1)/sqrt3,
    # (2,-1,-1)/sqrt6, (0,1,-1)/sqrt2
    a0, a1, a2 = _SQ3 * u0, _SQ3 * u1, _SQ3 * u2
    b0, b1, b2 = _SQ6 * e0, _SQ6 * e1, _SQ6 * e2
    c0, c1, c2 = _SQ2 * f0, _SQ2 * f1, _SQ2 * f2
    return (
        (a0 + 2.0 * b0, a1 + 2.0 * b1, a2 + 2.0 * b2),
        (a0 - b0 + c0, a1 - b1 + c1, a2 - b2 + c2),
        (a0 - b0 - c0, a1 - b1 - c1, a2 - b2 - c2),
    ), norm


def _mul(rows: Rows, v: Vec3) -> Vec3:
    """``R @ v`` for rows and a vector given as tuples."""
    v0, v1, v2 = v
    r0, r1, r2 = rows
    return (
        r0[0] * v0 + r0[1] * v1 + r0[2] * v2,
        r1[0] * v0 + r1[1] * v1 + r1[2] * v2,
        r2[0] * v0 + r2[1] * v1 + r2[2] * v2,
    )


def _mul_t(rows: Rows, s: Vec3) -> Vec3:
    """``R.T @ s``."""
    s0, s1, s2 = s
    r0, r1, r2 = rows
    return (
        r0[0] * s0 + r1[0] * s1 + r2[0] * s2,
        r0[1] * s0 + r1[1] * s1 + r2[1] * s2,
        r0[2] * s0 + r1[2] * s1 + r2[2] * s2,
    )


def normalized_frame(d_start: Vector, d_next: Vector | None = None) -> np.ndarray:
    """Rotation matrix ``R`` of ``S_i``: ``R @ v`` are the components of world ``v`` in ``S_i``.

    ``R @ d_start = |d_start|/sqrt3 (1, 1, 1)``; ``R @ d_next`` lies in the plane of
    ``(1, 1, 1)`` and ``(1, 0, 0)`` with a non-negative ``(2, -1, -1)`` component. When
    ``d_next`` is None, zero or parallel to ``d_start`` the roll about ``d_start`` is a fixed
    deterministic choice. Raises ValueError if ``d_start`` is zero (a dwell has no frame).
    """
    d = _vec3(d_start, "d_start")
    nxt = None if d_next is None else _vec3(d_next, "d_next")
    out = _frame_rows(d, nxt)
    if out is None:
        raise ValueError("d_start is zero: a dwell course has no normalized frame")
    return np.array(out[0])


def turn_angle(d_start: Vector, d_next: Vector) -> float:
    """Angle between ``D_i(0)`` and ``Delta_{i+1}(0)`` (0 if either is zero)."""
    a0, a1, a2 = _vec3(d_start, "d_start")
    b0, b1, b2 = _vec3(d_next, "d_next")
    c0, c1, c2 = a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0
    return math.atan2(math.sqrt(c0 * c0 + c1 * c1 + c2 * c2), a0 * b0 + a1 * b1 + a2 * b2)


def _k_rule(rho: float, c_low: float, c_high: float) -> float:
    return max(1.0, c_high * rho) if rho >= 1.0 else c_low * rho


def choose_k(
    rho: np.ndarray, *, c_low: float = C_LOW, c_high: float = C_HIGH, k_min: float = K_MIN
) -> np.ndarray:
    """Per-component ``k`` from ``rho`` (eqs. 12-13); ``k_min`` where ``rho <= 0``.

    :func:`course_end_velocity` passes ``k_min`` already scaled by the speed ratio.
    """
    rho = np.asarray(rho, dtype=float)
    k = np.where(rho >= 1.0, np.maximum(1.0, c_high * rho), c_low * rho)
    return np.where(rho > 0.0, k, k_min)


class EndVelocity(NamedTuple):
    """Diagnostics of :func:`course_end_velocity`.

    ``rule``: ``"sgc"`` (eqs. 12-13, also where the tangent rule falls back), ``"tangent"``
    (the chord through the neighbouring nails), ``"last"`` (no next course: user or average
    velocity),
    ``"rest"`` (arrive at rest: the next course is a dwell, or a zero end velocity was asked
    for) or ``"dwell"`` (this course is one). ``within_paper_assumption`` is False when the
    turn exceeds ``pi/6``, some ``rho <= 0``, or a user end velocity was clamped. ``frame``
    is ``S_i`` (None for a dwell); ``rho`` is NaN where it is not defined.
    """

    velocity: np.ndarray
    frame: np.ndarray | None
    rho: np.ndarray
    k: np.ndarray
    turn_angle: float
    within_paper_assumption: bool
    rule: str


_NAN3 = (math.nan, math.nan, math.nan)
_ZERO3 = (0.0, 0.0, 0.0)


DWELL_TOLERANCE = 1e-9
"""A next course shorter than this fraction of the current one is a dwell (repeated goal).

Goals that repeat a nail or an orientation often differ by rounding (a rotation composed with
its inverse is ~1e-16 from the identity); treated as a real course, that next course would be
1e16 times slower and drive ``k`` to ~1e-16, a profile that stops dead at the course start.
"""


def _negligible(nxt: tuple[float, float, float], d: tuple[float, float, float]) -> bool:
    n2 = nxt[0] * nxt[0] + nxt[1] * nxt[1] + nxt[2] * nxt[2]
    d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2]
    return n2 <= (DWELL_TOLERANCE * DWELL_TOLERANCE) * d2


def course_end_velocity(
    d_start: Vector,
    d_next: Vector | None,
    t_course: float,
    t_next: float | None,
    *,
    end_velocity: Vector | None = None,
    c_low: float = C_LOW,
    c_high: float = C_HIGH,
    k_min: float = K_MIN,
    rule: str = "paper",
) -> tuple[np.ndarray, EndVelocity]:
    """World end velocity ``D_i'(t_i)`` of course ``i`` and its diagnostics.

    ``rule``: ``"paper"`` (eqs. 12-13) or ``"tangent"`` (module docstring; it changes interior
    goals only and falls back to the paper's rule where it cannot be realised).

    ``d_start = D_i(0)``, ``d_next = Delta_{i+1}(0)`` (None for the last goal),
    ``t_course = t_i``, ``t_next = t_{i+1}``. Rules for what the paper does not cover:

    * last goal (``d_next`` None): ``end_velocity`` if given, else the course's average
      velocity ``-D_i(0)/t_i`` (``k = 1``); a zero ``end_velocity`` means arrive at rest;
      components of a given end velocity that do not point at the goal (``k < k_min`` in
      ``S_i``) are clamped to ``k_min``;
    * ``d_next == 0`` (the next goal repeats the nail, a dwell): arrive at rest, velocity 0
      (the course is then a :class:`HermiteProfile`, see :func:`solve_course_in_frame`);
    * ``d_start == 0`` (this course is a dwell): velocity 0;
    * ``rho <= 0`` (sharp turn): ``k = k_min * min(1, speed ratio of next to this course)``.

    Plain-float arithmetic: this runs every control step of the expert.
    """
    if rule not in END_RULES:
        raise ValueError(f"rule must be one of {list(END_RULES)}, got {rule!r}")
    d = _vec3(d_start, "d_start")
    if not (math.isfinite(t_course) and t_course > 0.0):
        raise ValueError(f"t_course must be finite and > 0, got {t_course!r}")
    nxt: tuple[float, float, float] | str | None = (
        None if d_next is None else _vec3(d_next, "d_next")
    )
    if isinstance(nxt, tuple) and _negligible(nxt, d):
        nxt = "rest"
    elif nxt is not None and (t_next is None or not (math.isfinite(t_next) and t_next > 0.0)):
        raise ValueError(f"t_next must be finite and > 0, got {t_next!r}")
    out = _frame_rows(d, nxt if isinstance(nxt, tuple) else None)
    if out is None:
        zeros = np.zeros(3)
        return zeros, EndVelocity(zeros, None, np.full(3, np.nan), zeros, 0.0, True, "dwell")
    rows, norm = out
    dj = norm * _SQ3
    avg = dj / t_course
    angle = 0.0
    if nxt is None:
        if end_velocity is None:
            v = np.array([-d[0] / t_course, -d[1] / t_course, -d[2] / t_course])
            return v, EndVelocity(v, np.array(rows), np.full(3, np.nan), np.ones(3), 0.0, True,
                                  "last")
        ve = _vec3(end_velocity, "end_velocity")
        if ve == _ZERO3:
            nxt = "rest"
        else:
            ks = [-c / avg for c in _mul(rows, ve)]
            rho = _NAN3
            within = min(ks) >= k_min
            rule = "last"
    if nxt == "rest":
        zeros = np.zeros(3)
        return zeros, EndVelocity(zeros, np.array(rows), np.full(3, np.nan), zeros, 0.0, True,
                                  "rest")
    if isinstance(nxt, tuple) and t_next is not None:  # t_next was checked with nxt above
        r0, r1, r2 = _mul(rows, nxt)
        rho = (r0 / t_next / avg, r1 / t_next / avg, r2 / t_next / avg)
        n0, n1, n2 = nxt
        speed_ratio = math.sqrt(n0 * n0 + n1 * n1 + n2 * n2) * t_course / (norm * t_next)
        k_floor = k_min * min(1.0, speed_ratio)
        ks = [_k_rule(r, c_low, c_high) if r > 0.0 else k_floor for r in rho]
        angle = turn_angle(d, nxt)
        within = angle <= PAPER_MAX_TURN + 1e-12 and min(rho) > 0.0
        tangent = None
        if rule == "tangent":
            tangent = _tangent_k(rows, d, nxt, norm, avg, t_course, t_next, k_min)
        if tangent is None:
            rule = "sgc"
        else:
            ks, rule = tangent, "tangent"
    else:
        ks = [k if k >= k_min else k_min for k in ks]
    v = np.array(_mul_t(rows, (-ks[0] * avg, -ks[1] * avg, -ks[2] * avg)))
    return v, EndVelocity(v, np.array(rows), np.array(rho), np.array(ks), angle, within, rule)


def tangent_speed(average: float, next_average: float) -> float:
    """Speed of the tangent rule at a goal from the average speeds of its two courses.

    Their mean, clamped to within :data:`PACE_STEP` of the course's own ``average`` either
    way: a graded change of pace (module docstring).
    """
    mean = 0.5 * (average + next_average)
    return min(max(mean, average / PACE_STEP), PACE_STEP * average)


def _tangent_k(
    rows: Rows, d: Vec3, nxt: Vec3, norm: float, avg: float, t_course: float,
    t_next: float, k_min: float,
) -> list[float] | None:
    """Per-component ``k`` of the tangent rule, or None where it falls back (module docstring).

    ``-(d + nxt)`` is ``nail_{i+1} - nail_{i-1}``: the chord through the goal's neighbours.
    """
    c0, c1, c2 = -(d[0] + nxt[0]), -(d[1] + nxt[1]), -(d[2] + nxt[2])
    chord = math.sqrt(c0 * c0 + c1 * c1 + c2 * c2)
    n0, n1, n2 = nxt
    speed = tangent_speed(norm / t_course, math.sqrt(n0 * n0 + n1 * n1 + n2 * n2) / t_next)
    if not chord > 1e-12 * norm:  # a hairpin: the next nail is the previous one
        return None
    scale = speed / chord
    ks = [-c / avg for c in _mul(rows, (c0 * scale, c1 * scale, c2 * scale))]
    return ks if min(ks) >= k_min else None


def condition_14(
    end_velocity: Vector, d_next: Vector, t_next: float, d_after: Vector | None = None
) -> bool:
    """Eq. 14: in ``S_{i+1}`` every component of the incoming velocity is slower than the
    next course's average, ``-D'_{i+1,j}(0) < D_{i+1,j}(0) / t_{i+1}``."""
    frame = normalized_frame(d_next, d_after)
    v = frame @ np.asarray(end_velocity, float)
    avg = float(np.linalg.norm(d_next)) * _SQ3 / t_next
    return bool(np.all(-v < avg))


class FrameCourse:
    """Three component profiles of one course in its frame ``S_i``; evaluates in world."""

    __slots__ = ("profiles", "duration", "_rows")

    def __init__(
        self, frame: np.ndarray | Rows, profiles: Sequence[Profile], duration: float
    ) -> None:
        """``frame``: ``S_i`` as a 3x3 array or as a tuple of three row tuples."""
        rows = frame.tolist() if isinstance(frame, np.ndarray) else frame
        self._rows: Rows = cast(Rows, tuple(tuple(float(x) for x in r) for r in rows))
        self.profiles = tuple(profiles)
        self.duration = duration

    @property
    def frame(self) -> np.ndarray:
        """``S_i`` as a rotation matrix (rows: the frame's axes in world)."""
        return np.array(self._rows)

    def state(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """World ``(D, D', D'')`` at scalar ``t`` seconds from the course start."""
        p0, p1, p2 = self.profiles
        s0, s1, s2 = p0.state(t), p1.state(t), p2.state(t)
        rows = self._rows
        return (
            np.array(_mul_t(rows, (s0[0], s1[0], s2[0]))),
            np.array(_mul_t(rows, (s0[1], s1[1], s2[1]))),
            np.array(_mul_t(rows, (s0[2], s1[2], s2[2]))),
        )

    def evaluate(self, t: float | np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """World ``(D, D', D'')`` at an array of times: each of shape ``t.shape + (3,)``."""
        parts = [p.evaluate(t) for p in self.profiles]
        out = []
        for q in range(3):
            comps = np.stack([np.asarray(parts[j][q], float) for j in range(3)], axis=-1)
            out.append(comps @ self.frame)
        return out[0], out[1], out[2]

    @property
    def branches(self) -> tuple[str, ...]:
        return tuple(p.branch for p in self.profiles)

    @property
    def k(self) -> np.ndarray:
        return np.array([getattr(p, "k", np.nan) for p in self.profiles])


_IDENTITY_ROWS = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))


def solve_course_in_frame(
    frame: np.ndarray | Rows | None,
    deviation_now: Vector,
    velocity_now: Vector,
    time_left: float,
    end_velocity: Vector,
    *,
    smooth_rest: bool = False,
) -> FrameCourse:
    """Solve the rest of a course from the current state (what a stateless expert calls).

    Per component ``j`` of ``S_i``: ``k'_j = -v_end_j T_left / D_j(now)``. Re-solving from a
    state on the plan returns the plan (time consistency). Components that cannot use SGC get
    a :class:`HermiteProfile` to ``(0, v_end_j)``: an end velocity of zero (arrive at rest),
    ``D_j(now) == 0``, or ``k'_j <= 0`` (only after a disturbance: the end velocity points
    away from the goal as seen from the current deviation), or ``gamma T - log k'`` outside the
    representable range of :meth:`CourseProfile.solve` (a deviation that is tiny next to the
    speed, e.g. 1e-30 m approached at 1 m/s). ``k'`` is not clamped to
    ``k_min`` here: that would break time consistency (``k_min`` applies at course start).
    A zero deviation, velocity and end velocity gives the dwell (:class:`HoldProfile`).
    ``frame`` None means the world frame. ``smooth_rest`` (the ``"matched"`` rule): arrive at
    rest on a :class:`RestQuarticProfile` (zero end acceleration) instead of the cubic.
    """
    if not (math.isfinite(time_left) and time_left > 0.0):
        raise ValueError(f"time_left must be finite and > 0, got {time_left!r}")
    rows: Any
    if frame is None:
        rows = _IDENTITY_ROWS
    else:
        rows = tuple(tuple(r) for r in (frame.tolist() if isinstance(frame, np.ndarray) else frame))
    profiles = _component_profiles(
        _mul(rows, _vec3(deviation_now, "deviation_now")),
        _mul(rows, _vec3(velocity_now, "velocity_now")),
        _mul(rows, _vec3(end_velocity, "end_velocity")),
        time_left,
        smooth_rest,
    )
    return FrameCourse(rows, profiles, time_left)


def next_deviation(
    rows: Rows, deviation_now: Vec3, velocity_now: Vec3, time_left: float, end_velocity: Vec3,
    t: float, smooth_rest: bool = False, lag: float = 0.0,
) -> Vec3:  # fmt: skip
    """World ``D(t)`` of the course :func:`solve_course_in_frame` would return, in plain floats.

    ``rows``: ``S_i`` as three row tuples (the identity for a dwell), the 3-vectors as tuples
    of floats; no validation beyond :meth:`CourseProfile.solve`'s. The expert calls this every
    control step; it shares the per-component rules with :func:`solve_course_in_frame`.
    ``lag``: the velocity is the mean over the last ``lag`` seconds (a semi-implicit step's
    chord), so the course is re-solved once from ``velocity_now + lag/2 D''(now)``.
    """
    if not time_left > 0.0:
        raise ValueError(f"time_left must be > 0, got {time_left!r}")
    d, v, ve = _mul(rows, deviation_now), _mul(rows, velocity_now), _mul(rows, end_velocity)
    p0, p1, p2 = _component_profiles(d, v, ve, time_left, smooth_rest)
    if lag > 0.0:  # ``velocity_now`` is the mean over the last ``lag`` s: centre it on now
        half = 0.5 * lag
        v = (v[0] + half * p0.state(0.0)[2], v[1] + half * p1.state(0.0)[2],
             v[2] + half * p2.state(0.0)[2])  # fmt: skip
        p0, p1, p2 = _component_profiles(d, v, ve, time_left, smooth_rest)
    return _mul_t(rows, (p0.state(t)[0], p1.state(t)[0], p2.state(t)[0]))


def _component_profiles(
    d: Vec3, v: Vec3, ve: Vec3, time_left: float, smooth_rest: bool = False
) -> tuple[Profile, Profile, Profile]:
    """The three component profiles of a course in ``S_i`` (components given in ``S_i``)."""
    rest = ve == _ZERO3
    if rest and d == _ZERO3 and v == _ZERO3:
        hold = HoldProfile(time_left)
        return hold, hold, hold
    if rest and smooth_rest:
        return (
            RestQuarticProfile(d[0], v[0], time_left),
            RestQuarticProfile(d[1], v[1], time_left),
            RestQuarticProfile(d[2], v[2], time_left),
        )
    return (
        _component_profile(d[0], v[0], ve[0], time_left, rest),
        _component_profile(d[1], v[1], ve[1], time_left, rest),
        _component_profile(d[2], v[2], ve[2], time_left, rest),
    )


def _component_profile(
    dj: float, vj: float, vej: float, time_left: float, rest: bool
) -> CourseProfile | HermiteProfile:
    """SGC where it applies, else the Hermite cubic (rules in :func:`solve_course_in_frame`)."""
    k = -vej * time_left / dj if dj != 0.0 else 0.0
    if rest or k <= 0.0:
        return HermiteProfile(dj, vj, time_left, vej)
    try:
        return CourseProfile.solve(dj, vj, time_left, k)
    except ValueError:  # gamma T - log k out of the representable range
        return HermiteProfile(dj, vj, time_left, vej)
