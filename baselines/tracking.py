"""Deadbeat tracking through PyBullet's free-body integrator.

PyBullet (double precision) advances one free body per substep of length ``h`` as

    v+ = v + h (F/m + g);                 x+ = x + h v+
    w+ = w + h Iw^-1 (tau - w x Iw w);    q+ = Exp(h w+) q

with ``Iw = R I R^T`` taken at the orientation before the substep. A force and a torque held
for the ``n`` substeps of one control period can therefore be chosen so that the body lands
*exactly* (to floating point) on a target position and orientation at the next control tick.
That is what makes the expert exact at goals rather than close.

The rotation part runs in plain-Python floats on purpose: these are 3-vectors and unit
quaternions evaluated a few dozen times per control step, where numpy's per-call overhead
costs more than the arithmetic (see ``scripts/bench_expert.py``).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

__all__ = [
    "held_acceleration_for_position",
    "simulate_rotation",
    "torque_for_orientation",
    "rotation_residual",
]

Vec = Sequence[float]
Quat = Sequence[float]


def held_acceleration_for_position(
    position: np.ndarray, velocity: np.ndarray, target: np.ndarray, h: float, n: int
) -> np.ndarray:
    """Constant acceleration over ``n`` semi-implicit substeps that ends at ``target``.

    ``x_n = x + n h v + h^2 a n (n + 1) / 2``, solved for ``a``.
    """
    return (target - position - (n * h) * velocity) * (2.0 / (h * h * n * (n + 1)))


def _quat_mul(a: Quat, b: Quat) -> tuple[float, float, float, float]:
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
        aw * bw - ax * bx - ay * by - az * bz,
    )


def _quat_exp(rx: float, ry: float, rz: float) -> tuple[float, float, float, float]:
    angle = math.sqrt(rx * rx + ry * ry + rz * rz)
    half = 0.5 * angle
    if angle < 1e-8:
        s = 0.5 - angle * angle / 48.0
    else:
        s = math.sin(half) / angle
    return (rx * s, ry * s, rz * s, math.cos(half))


def _quat_log(q: Quat) -> tuple[float, float, float]:
    x, y, z, w = q
    if w < 0.0:
        x, y, z, w = -x, -y, -z, -w
    vnorm = math.sqrt(x * x + y * y + z * z)
    if vnorm < 1e-12:
        scale = 2.0 / w
    else:
        scale = 2.0 * math.atan2(vnorm, w) / vnorm
    return (x * scale, y * scale, z * scale)


def _rotation_matrix(q: Quat) -> tuple[tuple[float, float, float], ...]:
    x, y, z, w = q
    return (
        (1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)),
        (2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)),
        (2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)),
    )


def _world_inertia_apply(rm, inertia: Vec, v: Vec, inverse: bool) -> tuple[float, float, float]:
    """``R diag(I) R^T v`` (or with ``1/I``) without forming the 3x3 product."""
    b0 = rm[0][0] * v[0] + rm[1][0] * v[1] + rm[2][0] * v[2]
    b1 = rm[0][1] * v[0] + rm[1][1] * v[1] + rm[2][1] * v[2]
    b2 = rm[0][2] * v[0] + rm[1][2] * v[1] + rm[2][2] * v[2]
    if inverse:
        b0, b1, b2 = b0 / inertia[0], b1 / inertia[1], b2 / inertia[2]
    else:
        b0, b1, b2 = b0 * inertia[0], b1 * inertia[1], b2 * inertia[2]
    return (
        rm[0][0] * b0 + rm[0][1] * b1 + rm[0][2] * b2,
        rm[1][0] * b0 + rm[1][1] * b1 + rm[1][2] * b2,
        rm[2][0] * b0 + rm[2][1] * b1 + rm[2][2] * b2,
    )


def simulate_rotation(
    orientation: Quat, angular_velocity: Vec, torque: Vec, inertia: Vec, h: float, n: int
) -> tuple[tuple[float, float, float, float], tuple[float, float, float]]:
    """Advance orientation and world angular velocity ``n`` substeps as PyBullet does.

    ``inertia`` is the principal inertia in the body frame (PyBullet's local inertia diagonal).
    """
    q = tuple(float(c) for c in orientation)
    wx, wy, wz = (float(c) for c in angular_velocity)
    tx, ty, tz = (float(c) for c in torque)
    for _ in range(n):
        rm = _rotation_matrix(q)
        lx, ly, lz = _world_inertia_apply(rm, inertia, (wx, wy, wz), inverse=False)
        gx = tx - (wy * lz - wz * ly)
        gy = ty - (wz * lx - wx * lz)
        gz = tz - (wx * ly - wy * lx)
        ax, ay, az = _world_inertia_apply(rm, inertia, (gx, gy, gz), inverse=True)
        wx, wy, wz = wx + h * ax, wy + h * ay, wz + h * az
        q = _quat_mul(_quat_exp(h * wx, h * wy, h * wz), q)
    return q, (wx, wy, wz)


def rotation_residual(orientation: Quat, target: Quat) -> tuple[float, float, float]:
    """World rotation vector taking ``target`` to ``orientation`` (``log(R R_target^T)``)."""
    return _quat_log(_quat_mul(orientation, _conjugate(target)))


def torque_for_orientation(
    orientation: Quat,
    angular_velocity: Vec,
    target: Quat,
    inertia: Vec,
    h: float,
    n: int,
    *,
    exact: bool = True,
    tolerance: float = 1e-14,
    max_iterations: int = 8,
) -> tuple[float, float, float]:
    """World torque, held ``n`` substeps, that lands the body on ``target``.

    Linear model: substep ``j`` (0-based) accelerates at ``Iw_j^-1 (tau - w x Iw_j w)`` and that
    acceleration moves the end rotation by ``h^2 (n - j)`` times itself, with ``Iw_j`` taken
    along the predicted free rotation. Summing gives ``A tau = b`` with
    ``A = h^2 sum_j (n - j) Iw_j^-1``: a thin rod's axial inertia makes ``A`` very anisotropic,
    and the body turning during the period mixes its directions, which a single inertia at the
    start of the period gets badly wrong. One correction step on the simulated model, with
    ``A`` as the Jacobian, follows (``exact=False``: between goals). With ``exact=True`` the
    correction repeats, switching to finite-difference Jacobians if it stalls, until the
    residual rotation is below ``tolerance`` (goal ticks).
    """
    w = (float(angular_velocity[0]), float(angular_velocity[1]), float(angular_velocity[2]))
    needed = _quat_log(_quat_mul(target, _conjugate(orientation)))
    step_turn = _quat_exp(h * w[0], h * w[1], h * w[2])
    a_matrix = np.zeros((3, 3))
    gyro_term = np.zeros(3)
    q = tuple(float(c) for c in orientation)
    inv_inertia = np.array([1.0 / inertia[0], 1.0 / inertia[1], 1.0 / inertia[2]])
    w_arr = np.array(w)
    for j in range(n):
        rm = np.array(_rotation_matrix(q))
        inv_world = (rm * inv_inertia) @ rm.T
        world = (rm * np.asarray(inertia, dtype=float)) @ rm.T
        weight = h * h * (n - j)
        a_matrix += weight * inv_world
        gyro_term += weight * (inv_world @ np.cross(w_arr, world @ w_arr))
        q = _quat_mul(step_turn, q)
    b = np.array(needed) - n * h * w_arr + gyro_term
    torque = np.linalg.solve(a_matrix, b)

    def residual(tau: np.ndarray) -> np.ndarray:
        reached, _ = simulate_rotation(orientation, w, tau, inertia, h, n)
        return np.array(rotation_residual(reached, target))

    r = residual(torque)
    iterations = max_iterations if exact else 1
    for i in range(iterations):
        if float(np.max(np.abs(r))) <= tolerance:
            break
        previous = float(np.max(np.abs(r)))
        jacobian = a_matrix if i < 2 else _residual_jacobian(residual, torque, r)
        torque = torque - np.linalg.solve(jacobian, r)
        r = residual(torque)
        if i >= 2 and float(np.max(np.abs(r))) >= previous:
            break
    return (float(torque[0]), float(torque[1]), float(torque[2]))


def _residual_jacobian(residual, torque: np.ndarray, r: np.ndarray) -> np.ndarray:
    """Forward-difference Jacobian of the end-rotation residual with respect to the torque."""
    step = 1e-7 * max(float(np.max(np.abs(torque))), 1.0)
    jacobian = np.empty((3, 3))
    for j in range(3):
        probe = torque.copy()
        probe[j] += step
        jacobian[:, j] = (residual(probe) - r) / step
    return jacobian


def _conjugate(q: Quat) -> tuple[float, float, float, float]:
    return (-q[0], -q[1], -q[2], q[3])


def _cross(a: Vec, b: Vec) -> tuple[float, float, float]:
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])
