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

import numpy as np
from numpy.typing import ArrayLike
from scipy.spatial.transform import Rotation

from sgc_env.paper import quaternion

__all__ = [
    "MAX_COURSE_ROTATION",
    "MAX_RELATIVE_ROTATION",
    "angular_acceleration",
    "course_pieces",
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


def split_rotation(
    rotation_vector: Sequence[float] | np.ndarray,
    t0: float,
    t1: float,
    control_frequency: int | None = None,
    where: str = "relative rotation",
) -> list[tuple[tuple[float, float, float], float]]:
    """A relative rotation from ``t0`` to ``t1`` as :func:`course_pieces` equal sub-rotations
    about its axis: ``(sub-rotation vector, end time)`` per course (the one splitter of the
    env's tracks and :func:`sgc_env.paper.plan.plan_body`).

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
    step = (rel[0] / m, rel[1] / m, rel[2] / m)
    if control_frequency is None:
        return [(step, t1 if i == m else t0 + (t1 - t0) * i / m) for i in range(1, m + 1)]
    f = control_frequency
    k0, k1 = round(t0 * f), round(t1 * f)
    if k1 - k0 < m:
        angle = math.sqrt(sum(c * c for c in rel))
        raise ValueError(
            f"{where}: a relative rotation of {angle:.6g} rad is split into {m} courses of at "
            f"most {MAX_COURSE_ROTATION:.4g} rad, which needs {m} control ticks before the goal "
            f"time but only {k1 - k0} are left; give the goal more time"
        )
    return [(step, (k0 + round(i * (k1 - k0) / m)) / f) for i in range(1, m + 1)]


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
