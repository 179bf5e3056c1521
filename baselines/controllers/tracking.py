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
from collections.abc import Callable, Sequence

import numpy as np

from sgc_env.paper import quaternion as quat

__all__ = [
    "held_acceleration_for_position",
    "simulate_rotation",
    "torque_for_orientation",
    "rotation_residual",
]

Vec = Sequence[float]
Quat = Sequence[float]
Vec3 = tuple[float, float, float]
ArrayOrFloat = np.ndarray | float


def held_acceleration_for_position(
    position: ArrayOrFloat, velocity: ArrayOrFloat, target: ArrayOrFloat, h: float, n: int
) -> ArrayOrFloat:
    """Constant acceleration over ``n`` semi-implicit substeps that ends at ``target``.

    ``x_n = x + n h v + h^2 a n (n + 1) / 2``, solved for ``a`` (per component: arrays or
    plain floats alike).
    """
    return (target - position - (n * h) * velocity) * (2.0 / (h * h * n * (n + 1)))


def _world_inertia_apply(rm, inertia: Vec, v: Vec, inverse: bool) -> Vec3:
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
) -> tuple[tuple[float, float, float, float], Vec3]:
    """Advance orientation and world angular velocity ``n`` substeps as PyBullet does.

    ``inertia`` is the principal inertia in the body frame (PyBullet's local inertia diagonal).
    """
    q = (float(orientation[0]), float(orientation[1]), float(orientation[2]),
         float(orientation[3]))  # fmt: skip
    wx, wy, wz = (float(c) for c in angular_velocity)
    tx, ty, tz = (float(c) for c in torque)
    for _ in range(n):
        rm = quat.to_matrix(q)
        lx, ly, lz = _world_inertia_apply(rm, inertia, (wx, wy, wz), inverse=False)
        gx = tx - (wy * lz - wz * ly)
        gy = ty - (wz * lx - wx * lz)
        gz = tz - (wx * ly - wy * lx)
        ax, ay, az = _world_inertia_apply(rm, inertia, (gx, gy, gz), inverse=True)
        wx, wy, wz = wx + h * ax, wy + h * ay, wz + h * az
        q = quat.mul(quat.exp((h * wx, h * wy, h * wz)), q)
    return q, (wx, wy, wz)


def _simulate_axisymmetric(
    q: Quat, w: Vec, torque: Vec, inertia: Vec, h: float, n: int
) -> tuple[Quat, Vec3]:
    """:func:`simulate_rotation` for ``I0 == I1`` with ``Iw = I0 Id + (I2 - I0) a a^T``.

    Equal to the matrix form up to rounding; about half its cost.
    """
    i0, i2 = inertia[0], inertia[2]
    inv0, d = 1.0 / i0, 1.0 / i2 - 1.0 / i0
    gap = i2 - i0
    wx, wy, wz = w
    tx, ty, tz = torque
    for _ in range(n):
        x, y, z, qw = q
        ax, ay, az = 2.0 * (x * z + y * qw), 2.0 * (y * z - x * qw), 1.0 - 2.0 * (x * x + y * y)
        along = gap * (ax * wx + ay * wy + az * wz)
        lx, ly, lz = i0 * wx + along * ax, i0 * wy + along * ay, i0 * wz + along * az
        gx = tx - (wy * lz - wz * ly)
        gy = ty - (wz * lx - wx * lz)
        gz = tz - (wx * ly - wy * lx)
        axial = d * (ax * gx + ay * gy + az * gz)
        wx += h * (gx * inv0 + axial * ax)
        wy += h * (gy * inv0 + axial * ay)
        wz += h * (gz * inv0 + axial * az)
        q = quat.mul(quat.exp((h * wx, h * wy, h * wz)), q)
    return q, (wx, wy, wz)


def rotation_residual(orientation: Quat, target: Quat) -> Vec3:
    """World rotation vector taking ``target`` to ``orientation`` (``log(R R_target^T)``)."""
    return quat.log(quat.mul(orientation, quat.conjugate(target)))


def torque_for_orientation(
    orientation: Quat,
    angular_velocity: Vec,
    target: Quat,
    inertia: Vec,
    h: float,
    n: int,
    *,
    exact: bool = True,
    refine: bool = True,
    tolerance: float = 1e-14,
    max_iterations: int = 8,
) -> Vec3:
    """World torque, held ``n`` substeps, that lands the body on ``target``.

    Linear model: substep ``j`` (0-based) accelerates at ``Iw_j^-1 (tau - w x Iw_j w)`` and that
    acceleration moves the end rotation by ``h^2 (n - j)`` times itself, with ``Iw_j`` taken
    along the predicted free rotation. Summing gives ``A tau = b`` with
    ``A = h^2 sum_j (n - j) Iw_j^-1``: a thin rod's axial inertia makes ``A`` very anisotropic,
    and the body turning during the period mixes its directions, which a single inertia at the
    start of the period gets badly wrong. With ``exact=False`` (between goals) that first guess
    is returned as is (``refine=False``) or after one correction step on the simulated model
    with ``A`` as the Jacobian. With ``exact=True`` the correction repeats, switching to
    finite-difference Jacobians if it stalls, until the residual rotation is below
    ``tolerance`` (goal ticks).
    """
    w = (float(angular_velocity[0]), float(angular_velocity[1]), float(angular_velocity[2]))
    q = (float(orientation[0]), float(orientation[1]), float(orientation[2]),
         float(orientation[3]))  # fmt: skip
    target = (float(target[0]), float(target[1]), float(target[2]), float(target[3]))
    needed = quat.log(quat.mul(target, quat.conjugate(q)))
    if inertia[0] == inertia[1]:
        a_matrix, (gx, gy, gz) = _linear_model_axisymmetric(q, w, inertia, h, n)
    else:
        a_matrix, (gx, gy, gz) = _linear_model(q, w, inertia, h, n)
    nh = n * h
    b = (needed[0] - nh * w[0] + gx, needed[1] - nh * w[1] + gy, needed[2] - nh * w[2] + gz)
    inverse_a = _inverse3(a_matrix)
    torque = _matvec(inverse_a, b)
    if not (exact or refine):
        return torque

    # between goals the correction runs on the cheaper closed form of an axisymmetric body;
    # goal ticks use the matrix form, which follows PyBullet's own arithmetic more closely
    simulate: Callable[..., tuple[Quat, Vec3]] = simulate_rotation
    if not exact and inertia[0] == inertia[1]:
        simulate = _simulate_axisymmetric

    def residual(tau: Vec) -> Vec3:
        reached, _ = simulate(q, w, tau, inertia, h, n)
        return rotation_residual(reached, target)

    r = residual(torque)
    if not exact:  # one correction step; its residual is not needed
        if max(abs(r[0]), abs(r[1]), abs(r[2])) <= tolerance:
            return torque
        step = _matvec(inverse_a, r)
        return (torque[0] - step[0], torque[1] - step[1], torque[2] - step[2])
    for i in range(max_iterations):
        size = max(abs(r[0]), abs(r[1]), abs(r[2]))
        if size <= tolerance:
            break
        if i < 2:
            step = _matvec(inverse_a, r)
        else:
            jacobian = _residual_jacobian(residual, np.array(torque), np.array(r))
            step = tuple(np.linalg.solve(jacobian, np.array(r)))
        torque = (torque[0] - step[0], torque[1] - step[1], torque[2] - step[2])
        r = residual(torque)
        if i >= 2 and max(abs(r[0]), abs(r[1]), abs(r[2])) >= size:
            break
    return (float(torque[0]), float(torque[1]), float(torque[2]))


def _linear_model(q: Quat, w: Vec3, inertia: Vec, h: float, n: int):
    """``A`` and ``b``'s gyroscopic term along the predicted free rotation (any inertia)."""
    step_turn = quat.exp((h * w[0], h * w[1], h * w[2]))
    a_matrix = [[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]]
    gx = gy = gz = 0.0
    i0, i1, i2 = 1.0 / inertia[0], 1.0 / inertia[1], 1.0 / inertia[2]
    for j in range(n):
        rm = quat.to_matrix(q)
        weight = h * h * (n - j)
        for r in range(3):
            ra = rm[r]
            for c in range(r, 3):
                rc = rm[c]
                value = weight * (ra[0] * rc[0] * i0 + ra[1] * rc[1] * i1 + ra[2] * rc[2] * i2)
                a_matrix[r][c] += value
                if c != r:
                    a_matrix[c][r] += value
        lx, ly, lz = _world_inertia_apply(rm, inertia, w, inverse=False)
        cx, cy, cz = _cross(w, (lx, ly, lz))
        ax, ay, az = _world_inertia_apply(rm, inertia, (cx, cy, cz), inverse=True)
        gx, gy, gz = gx + weight * ax, gy + weight * ay, gz + weight * az
        q = quat.mul(step_turn, q)
    return a_matrix, (gx, gy, gz)


def _linear_model_axisymmetric(q: Quat, w: Vec3, inertia: Vec, h: float, n: int):
    """Same as :func:`_linear_model` for ``I0 == I1`` (rods, spheres), in closed form.

    With ``a`` the body z axis in world, ``Iw^-1 = Id / I0 + (1/I2 - 1/I0) a a^T`` and the
    gyroscopic acceleration ``Iw^-1 (w x Iw w) = (I2 - I0)/I0 (a.w) (w x a)``, so only ``a``
    has to follow the predicted free rotation: about a third of the general loop's work.
    """
    x, y, z, qw = q
    ax, ay, az = 2.0 * (x * z + y * qw), 2.0 * (y * z - x * qw), 1.0 - 2.0 * (x * x + y * y)
    inv0 = 1.0 / inertia[0]
    diag = h * h * inv0 * (n * (n + 1) // 2)
    if inertia[2] == inertia[0]:
        return [[diag, 0.0, 0.0], [0.0, diag, 0.0], [0.0, 0.0, diag]], (0.0, 0.0, 0.0)
    step_turn = quat.exp((h * w[0], h * w[1], h * w[2]))
    wx, wy, wz = w
    m00 = m01 = m02 = m11 = m12 = m22 = 0.0
    sx = sy = sz = 0.0
    for j in range(n):
        weight = float(n - j)
        m00 += weight * ax * ax
        m01 += weight * ax * ay
        m02 += weight * ax * az
        m11 += weight * ay * ay
        m12 += weight * ay * az
        m22 += weight * az * az
        along = weight * (ax * wx + ay * wy + az * wz)
        sx, sy, sz = sx + along * ax, sy + along * ay, sz + along * az
        if j + 1 < n:
            ax, ay, az = quat.rotate(step_turn, (ax, ay, az))
    d = h * h * (1.0 / inertia[2] - inv0)
    g = h * h * (inertia[2] - inertia[0]) * inv0
    a_matrix = [
        [diag + d * m00, d * m01, d * m02],
        [d * m01, diag + d * m11, d * m12],
        [d * m02, d * m12, diag + d * m22],
    ]
    return a_matrix, (g * (wy * sz - wz * sy), g * (wz * sx - wx * sz), g * (wx * sy - wy * sx))


def _inverse3(m: list[list[float]]) -> tuple[Vec3, Vec3, Vec3]:
    """Inverse of a 3x3 matrix by cofactors (plain floats: this runs every control step)."""
    (a, b, c), (d, e, f), (g, hh, i) = m
    co0, co1, co2 = e * i - f * hh, f * g - d * i, d * hh - e * g
    det = a * co0 + b * co1 + c * co2
    if det == 0.0 or not math.isfinite(det):
        raise ValueError("singular inertia model: cannot solve for a torque")
    inv = 1.0 / det
    return (
        (co0 * inv, (c * hh - b * i) * inv, (b * f - c * e) * inv),
        (co1 * inv, (a * i - c * g) * inv, (c * d - a * f) * inv),
        (co2 * inv, (b * g - a * hh) * inv, (a * e - b * d) * inv),
    )


def _matvec(m, v: Vec) -> Vec3:
    return (
        m[0][0] * v[0] + m[0][1] * v[1] + m[0][2] * v[2],
        m[1][0] * v[0] + m[1][1] * v[1] + m[1][2] * v[2],
        m[2][0] * v[0] + m[2][1] * v[1] + m[2][2] * v[2],
    )


def _residual_jacobian(residual, torque: np.ndarray, r: np.ndarray) -> np.ndarray:
    """Forward-difference Jacobian of the end-rotation residual with respect to the torque."""
    step = 1e-7 * max(float(np.max(np.abs(torque))), 1.0)
    jacobian = np.empty((3, 3))
    for j in range(3):
        probe = torque.copy()
        probe[j] += step
        jacobian[:, j] = (np.array(residual(probe)) - r) / step
    return jacobian


def _cross(a: Vec, b: Vec) -> Vec3:
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])
