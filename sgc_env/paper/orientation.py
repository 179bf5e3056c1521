"""Orientation deviations as rotation vectors (world frame), somersaults and Jacobians.

Convention (design.md): ``R_current = Exp(phi) R_goal``, so ``phi = Log(R_current R_goal^T)``
unwrapped to stay continuous; a somersault's ``phi`` may be longer than ``pi``. With ``R_goal``
fixed, ``Rdot R^T = [J_l(phi) phi_dot]x``, so the world angular velocity is
``omega = J_l(phi) phi_dot`` with the left Jacobian of SO(3)

    J_l(phi) = I + A(theta) [phi]x + B(theta) [phi]x^2,
    A = (1 - cos theta) / theta^2,  B = (theta - sin theta) / theta^3,  theta = |phi|,

and ``omega_dot = J_l phi_ddot + (d/dt J_l) phi_dot``. ``J_l`` is singular where
``theta = 2 pi n`` (n >= 1); :func:`left_jacobian_inverse` raises there.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import cast

import numpy as np
from numpy.typing import ArrayLike
from scipy.spatial.transform import Rotation

from sgc_env.paper import quaternion

__all__ = [
    "MAX_COURSE_ROTATION",
    "MAX_RELATIVE_ROTATION",
    "SMOOTH_PIECE_ANGLE",
    "angular_acceleration",
    "course_pieces",
    "goal_rotations",
    "neighbour_paces",
    "rotation_profile",
    "angular_velocity",
    "left_jacobian",
    "left_jacobian_inverse",
    "left_jacobian_inverse_apply",
    "orientation_deviation",
    "quat_to_rotvec",
    "rotvec_to_quat",
    "split_rotation",
]

_TWO_PI = 2.0 * math.pi
Vector = Sequence[float] | np.ndarray

MAX_COURSE_ROTATION = 2.0 * math.pi / 3.0
"""Longest rotation one orientation course may make; longer relative rotations are split.

``J_l`` is singular on the shell ``|phi| = 2 pi``: a course that starts there cannot carry an
angular velocity across its axis (the plan would start at the wrong angular velocity), and
from measured states every rotation near the identity has a representative there only along
one axis. Planner and env therefore split a somersault into equal sub-rotations about the
same axis, each one a course of its own (:func:`split_rotation`, one splitter for both).
"""

MAX_RELATIVE_ROTATION = 64.0 * math.pi
"""Longest relative rotation of one goal (32 turns, 96 courses): bounds the planner's work."""


def course_pieces(rotation_vector: ArrayLike) -> int:
    """How many equal courses a relative rotation is split into (see MAX_COURSE_ROTATION)."""
    angle = float(np.linalg.norm(np.asarray(rotation_vector, dtype=float)))
    if not angle <= MAX_RELATIVE_ROTATION:
        raise ValueError(
            f"relative rotation of {angle:.6g} rad is longer than {MAX_RELATIVE_ROTATION:.6g} "
            "rad (32 turns), the most one goal may ask"
        )
    return max(1, math.ceil(angle / MAX_COURSE_ROTATION - 1e-12))


SMOOTH_PIECE_ANGLE = math.pi / 8.0
"""Target rotation of one sub-course of a smooth split (:func:`split_rotation` with paces):
short enough that the sub-courses' average rates follow the rate profile closely."""

_MAX_PIECES = math.ceil(MAX_RELATIVE_ROTATION / MAX_COURSE_ROTATION)

SMOOTH_PIECE_TICKS = 4
"""Fewest control ticks per sub-course of a smooth split (fewer pieces when time is short)."""


PACE_FLOOR = 0.25
"""Smallest pace of a smooth split's ends, as a share of its mean rate (rotation_profile)."""


def rotation_profile(
    s: float | np.ndarray, rate_in: float, rate_out: float, mean: float
) -> float | np.ndarray:
    """Fraction of a split rotation done at normalised time ``s`` in [0, 1] (1 at ``s = 1``).

    The rate ``r(s) = rate_in (1 - h) + rate_out h + c h'`` with ``h`` the minimum-jerk step
    ``10 s^3 - 15 s^4 + 6 s^5``: it starts at ``rate_in``, ends at ``rate_out``, has zero
    slope (angular acceleration) at both ends and its bump ``c h'`` makes the mean ``mean``.
    ``rate_in`` and ``rate_out`` are clamped to ``[mean / 4, 2 mean]``, which keeps the rate
    above ``mean / 8`` (no stop, no turning back) and at most ``2 mean``. The floor keeps the
    first and last pieces from shrinking to nothing (a spin from rest, or to a dwell): a piece
    of almost no angle entered at speed would have to brake violently within it.
    """
    w0 = min(max(rate_in, PACE_FLOOR * mean), 2.0 * mean)
    w1 = min(max(rate_out, PACE_FLOOR * mean), 2.0 * mean)
    c = mean - 0.5 * (w0 + w1)
    s2 = s * s
    h = s2 * s * (10.0 - 15.0 * s + 6.0 * s2)
    big_h = s2 * s2 * (2.5 - 3.0 * s + s2)
    return (w0 * s + (w1 - w0) * big_h + c * h) / mean


def split_rotation(
    rotation_vector: Sequence[float] | np.ndarray,
    t0: float,
    t1: float,
    control_frequency: int | None = None,
    where: str = "relative rotation",
    *,
    rate_in: float | None = None,
    rate_out: float | None = None,
) -> list[tuple[tuple[float, float, float], float]]:
    """A relative rotation from ``t0`` to ``t1`` as sub-rotations about its axis:
    ``(sub-rotation vector, end time)`` per course (the one splitter of the env's tracks and
    :func:`sgc_env.paper.plan.plan_body`).

    Without paces: :func:`course_pieces` equal sub-rotations (the constant rate of the
    original split). With ``rate_in`` and ``rate_out`` (rad/s along the axis: the paces of
    the neighbouring orientation courses, see :func:`neighbour_paces`) a *smooth split*: about
    one piece per :data:`SMOOTH_PIECE_ANGLE`, at least :data:`SMOOTH_PIECE_TICKS` ticks each,
    sub-rotations unequal so that their average rates follow :func:`rotation_profile` from
    the incoming to the outgoing pace. The pace change is then spread over the pieces instead
    of one sub-course's sharp acceleration (docs/smoothness.md).

    With ``control_frequency`` the courses are timed as the env times them, on its control
    grid: course ``i`` of ``m`` ends on tick ``k0 + round(i (k1 - k0) / m)`` with ``k0, k1``
    the ticks of ``t0, t1``, and fewer ticks than courses is an error naming ``where``.
    Without it they are spaced evenly in continuous time; the last ends exactly at ``t1``.
    """
    rel = tuple(float(c) for c in rotation_vector)
    try:
        m = course_pieces(rel)
    except ValueError as exc:
        raise ValueError(f"{where}: {exc}") from None
    angle = math.sqrt(sum(c * c for c in rel))
    f = control_frequency
    k0, k1 = (round(t0 * f), round(t1 * f)) if f is not None else (0, 0)
    if f is not None and k1 - k0 < m:
        raise ValueError(
            f"{where}: a relative rotation of {angle:.6g} rad is split into {m} courses of at "
            f"most {MAX_COURSE_ROTATION:.4g} rad, which needs {m} control ticks before the goal "
            f"time but only {k1 - k0} are left; give the goal more time"
        )
    smooth = rate_in is not None and rate_out is not None and m > 1
    if smooth:
        # no more courses than the longest equal split (96): bounds the planner's work
        wanted = min(math.ceil(angle / SMOOTH_PIECE_ANGLE - 1e-12), _MAX_PIECES)
        m = max(m, min(wanted, (k1 - k0) // SMOOTH_PIECE_TICKS) if f is not None else wanted)
    if f is None:
        ends = [t1 if i == m else t0 + (t1 - t0) * i / m for i in range(1, m + 1)]
        fractions = [i / m for i in range(m + 1)]
    else:
        ticks = [k0 + round(i * (k1 - k0) / m) for i in range(m + 1)]
        ends = [k / f for k in ticks[1:]]
        fractions = [(k - k0) / (k1 - k0) for k in ticks]
    if not smooth:
        step = (rel[0] / m, rel[1] / m, rel[2] / m)
        return [(step, end) for end in ends]
    mean = angle / (t1 - t0)
    done = [
        float(rotation_profile(s, cast(float, rate_in), cast(float, rate_out), mean))
        for s in fractions
    ]
    done[-1] = 1.0
    if max(b - a for a, b in zip(done[:-1], done[1:], strict=True)) * angle > (
        MAX_COURSE_ROTATION
    ):  # too few ticks for the profile's bulge: the constant rate still fits
        return split_rotation(rel, t0, t1, control_frequency, where)
    return [
        ((rel[0] * (b - a), rel[1] * (b - a), rel[2] * (b - a)), end)
        for a, b, end in zip(done[:-1], done[1:], ends, strict=True)
    ]


def neighbour_paces(
    rotations: Sequence[Sequence[float]],
    times: Sequence[float],
    angular_velocity: Sequence[float] | np.ndarray,
    end_angular_velocity: Sequence[float] | np.ndarray | None,
) -> list[tuple[float, float]]:
    """``(rate_in, rate_out)`` per goal of an orientation track, for :func:`split_rotation`.

    ``rotations``: each goal's rotation from the previous one (a rotation vector, longer than
    pi for a somersault), ``times`` the goals' times (the track starts at 0). The paces are
    the average rates (angle / duration) of the courses before and after the goal; before the
    first, the initial angular velocity along the first rotation's axis; after the last, the
    end angular velocity along its axis (None: the last course's own average). Env and
    planner both call this, so they split a somersault alike.
    """
    angles = [math.sqrt(sum(float(c) * float(c) for c in r)) for r in rotations]
    durations = np.diff(np.concatenate(([0.0], np.asarray(times, float)))).tolist()
    rates = [a / d for a, d in zip(angles, durations, strict=True)]
    out = []
    for j, rate in enumerate(rates):
        before = _axis_rate(rotations[0], angular_velocity) if j == 0 else rates[j - 1]
        if j + 1 < len(rates):
            after = rates[j + 1]
        elif end_angular_velocity is None:
            after = rate
        else:
            after = _axis_rate(rotations[j], end_angular_velocity)
        out.append((before, after))
    return out


def goal_rotations(
    start: Sequence[float],
    goals: Sequence[tuple[Vector | None, Vector | None]],
) -> list[tuple[float, float, float]]:
    """Each orientation goal's rotation from the previous one (a rotation vector), from the
    start quaternion (xyzw) and ``(orientation, relative_rotation)`` per goal, exactly one of
    them given: the relative rotation itself, or the principal rotation to the orientation.
    The input of :func:`neighbour_paces`."""
    out = []
    q = tuple(float(c) for c in start)
    for orientation, relative in goals:
        if relative is not None:
            r = (float(relative[0]), float(relative[1]), float(relative[2]))
            q = quaternion.mul(quaternion.exp_normalized(r), q)
        else:
            target = tuple(float(c) for c in cast(Sequence[float], orientation))
            r = quaternion.log(quaternion.mul_conjugate(target, q))
            q = target
        out.append(r)
    return out


def _axis_rate(
    rotation_vector: Sequence[float], angular_velocity: Sequence[float] | np.ndarray
) -> float:
    """Component of an angular velocity along a rotation's axis (0 for a zero rotation)."""
    angle = math.sqrt(sum(float(c) * float(c) for c in rotation_vector))
    if angle == 0.0:
        return 0.0
    dot = sum(float(a) * float(w) for a, w in zip(rotation_vector, angular_velocity, strict=True))
    return dot / angle


def _skew(v: np.ndarray) -> np.ndarray:
    x, y, z = v
    return np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])


def _coefficients(theta: float) -> tuple[float, float, float, float]:
    """``A, B`` and ``A'/theta, B'/theta`` (Taylor series below 0.05 against cancellation)."""
    if theta < 0.05:
        t2 = theta * theta
        t4 = t2 * t2
        t6 = t4 * t2
        return (
            0.5 - t2 / 24.0 + t4 / 720.0 - t6 / 40320.0 + t4 * t4 / 3628800.0,
            1.0 / 6.0 - t2 / 120.0 + t4 / 5040.0 - t6 / 362880.0 + t4 * t4 / 39916800.0,
            -1.0 / 12.0 + t2 / 180.0 - t4 / 6720.0 + t6 / 453600.0,
            -1.0 / 60.0 + t2 / 1260.0 - t4 / 60480.0 + t6 / 4989600.0,
        )
    s = math.sin(theta)
    one_minus_c = 2.0 * math.sin(0.5 * theta) ** 2
    t2 = theta * theta
    a = one_minus_c / t2
    b = (theta - s) / (t2 * theta)
    da = (theta * s - 2.0 * one_minus_c) / (t2 * t2)
    db = (one_minus_c * theta - 3.0 * (theta - s)) / (t2 * t2 * theta)
    return a, b, da, db


def left_jacobian(phi: ArrayLike) -> np.ndarray:
    """``J_l(phi)``: ``omega = J_l(phi) phi_dot`` for ``R = Exp(phi) R_goal``."""
    phi = np.asarray(phi, dtype=float)
    a, b, _, _ = _coefficients(float(np.linalg.norm(phi)))
    k = _skew(phi)
    return np.eye(3) + a * k + b * (k @ k)


def left_jacobian_inverse(phi: ArrayLike) -> np.ndarray:
    """``J_l(phi)^-1 = I - [phi]x / 2 + (1/theta^2 - (1 + cos)/(2 theta sin)) [phi]x^2``.

    Raises ValueError within 1e-9 rad of ``theta = 2 pi n`` where ``J_l`` is singular.
    """
    phi = np.asarray(phi, dtype=float)
    e = _inverse_coefficient(float(np.linalg.norm(phi)))
    k = _skew(phi)
    return np.eye(3) - 0.5 * k + e * (k @ k)


def _inverse_coefficient(theta: float) -> float:
    """``1/theta^2 - (1 + cos)/(2 theta sin)`` of ``J_l^-1``; ValueError where singular."""
    if theta < 0.05:
        t2 = theta * theta
        return 1.0 / 12.0 + t2 / 720.0 + t2 * t2 / 30240.0 + t2 * t2 * t2 / 1209600.0
    n = round(theta / _TWO_PI)
    if n >= 1 and abs(theta - n * _TWO_PI) < 1e-9:
        raise ValueError(
            f"phi has length {theta!r} = 2*pi*{n}: the left Jacobian is singular there"
        )
    return 1.0 / (theta * theta) - (1.0 + math.cos(theta)) / (2.0 * theta * math.sin(theta))


def left_jacobian_inverse_apply(
    phi: Sequence[float] | np.ndarray, omega: Sequence[float] | np.ndarray
) -> tuple[float, float, float]:
    """``phi_dot`` with ``J_l(phi) phi_dot = omega``, in plain floats (the expert's per-step
    path: ``omega - phi x omega / 2 + e phi x (phi x omega)``, no 3x3 matrix).

    Least squares where ``J_l`` is singular (``|phi| = 2 pi n``: the component of ``omega``
    across the axis cannot be represented).
    """
    px, py, pz = phi
    wx, wy, wz = omega
    try:
        e = _inverse_coefficient(math.sqrt(px * px + py * py + pz * pz))
    except ValueError:
        solution = np.linalg.lstsq(left_jacobian(phi), np.asarray(omega, float), rcond=None)
        return tuple(solution[0].tolist())
    cx, cy, cz = py * wz - pz * wy, pz * wx - px * wz, px * wy - py * wx
    ccx, ccy, ccz = py * cz - pz * cy, pz * cx - px * cz, px * cy - py * cx
    return (wx - 0.5 * cx + e * ccx, wy - 0.5 * cy + e * ccy, wz - 0.5 * cz + e * ccz)


def angular_velocity(phi: ArrayLike, phi_dot: ArrayLike) -> np.ndarray:
    """World angular velocity ``J_l(phi) phi_dot``."""
    return left_jacobian(phi) @ np.asarray(phi_dot, dtype=float)


def angular_acceleration(phi: ArrayLike, phi_dot: ArrayLike, phi_ddot: ArrayLike) -> np.ndarray:
    """``omega_dot = J_l phi_ddot + (d/dt J_l) phi_dot``.

    ``(d/dt J_l) phi_dot = (A'/theta)(phi.phi_dot)(phi x phi_dot)
    + (B'/theta)(phi.phi_dot)(phi x (phi x phi_dot)) + B phi_dot x (phi x phi_dot)``
    (the ``[phi_dot]x phi_dot`` term vanishes).
    """
    phi = np.asarray(phi, dtype=float)
    pd = np.asarray(phi_dot, dtype=float)
    pdd = np.asarray(phi_ddot, dtype=float)
    a, b, da, db = _coefficients(float(np.linalg.norm(phi)))
    k = _skew(phi)
    j = np.eye(3) + a * k + b * (k @ k)
    dot = float(phi @ pd)
    c1 = np.cross(phi, pd)
    return j @ pdd + da * dot * c1 + db * dot * np.cross(phi, c1) + b * np.cross(pd, c1)


def rotvec_to_quat(phi: ArrayLike) -> np.ndarray:
    """Quaternion ``(x, y, z, w)`` of the rotation vector ``phi`` (any length)."""
    return Rotation.from_rotvec(np.asarray(phi, dtype=float)).as_quat()


def quat_to_rotvec(quat: ArrayLike) -> np.ndarray:
    """Principal rotation vector (``|phi| <= pi``) of a quaternion ``(x, y, z, w)``."""
    return Rotation.from_quat(np.asarray(quat, dtype=float)).as_rotvec()


def orientation_deviation(
    current: Rotation, goal: Rotation, phi_prev: Sequence[float] | None = None
) -> np.ndarray:
    """``phi = Log(R_current R_goal^T)``, unwrapped against ``phi_prev`` when given."""
    phi = (current * goal.inv()).as_rotvec()
    return phi if phi_prev is None else np.array(quaternion.unwrap_rotvec(phi, phi_prev))
