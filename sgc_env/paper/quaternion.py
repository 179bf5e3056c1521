"""Unit quaternions ``(x, y, z, w)`` as plain-Python tuples (the one copy of these helpers).

The expert's control step, the tracking model and the env's per-step bookkeeping rotate a few
3-vectors each; on single vectors plain floats are several times cheaper than numpy calls
(about 0.1 us per float operation against 1-5 us per numpy call) and scipy's ``Rotation``
(about 10 us per call). ``scripts/bench_expert.py`` measures the effect.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

from .elementwise import all_, any_, atan2, rint, sqrt, where, where3

__all__ = [
    "conjugate", "exp", "exp_normalized", "log", "mul", "mul_conjugate", "rotate", "to_matrix",
    "unwrap_rotvec",
]  # fmt: skip

Quat = tuple[float, float, float, float]
Vec3 = tuple[float, float, float]
TWO_PI = 2.0 * math.pi


def mul(a: Sequence[float], b: Sequence[float]) -> Quat:
    """Hamilton product ``a * b``: the rotation ``R_a R_b``."""
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
        aw * bw - ax * bx - ay * by - az * bz,
    )


def mul_conjugate(a: Sequence[float], b: Sequence[float]) -> Quat:
    """``a * conj(b)``: the rotation ``R_a R_b^T``, bit for bit ``mul(a, conjugate(b))``.

    Written out because the env evaluates it for every body on every control step.
    """
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (
        -aw * bx + ax * bw - ay * bz + az * by,
        -aw * by + ax * bz + ay * bw - az * bx,
        -aw * bz - ax * by + ay * bx + az * bw,
        aw * bw + ax * bx + ay * by + az * bz,
    )


def conjugate(q: Sequence[float]) -> Quat:
    """``q^-1`` of a unit quaternion."""
    return (-q[0], -q[1], -q[2], q[3])


def exp(r: Sequence[float]) -> Quat:
    """Quaternion of the rotation vector ``r`` (``Exp``), the form PyBullet's integrator uses.

    Below 1e-8 rad the ``sin(a/2)/a`` factor is its Taylor series (no cancellation).
    """
    rx, ry, rz = r
    angle = math.sqrt(rx * rx + ry * ry + rz * rz)
    if angle < 1e-8:
        s = 0.5 - angle * angle / 48.0
    else:
        s = math.sin(0.5 * angle) / angle
    return (rx * s, ry * s, rz * s, math.cos(0.5 * angle))


def exp_normalized(r: Sequence[float]) -> Quat:
    """:func:`exp` renormalised to unit length (goal quaternions compiled by the env)."""
    q = exp(r)
    n = math.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
    return (q[0] / n, q[1] / n, q[2] / n, q[3] / n)


def log(q: Sequence[Any]) -> tuple[Any, Any, Any]:
    """Principal rotation vector (angle in ``[0, pi]``) of a unit quaternion (``Log``); also
    elementwise on arrays of components (:mod:`sgc_env.paper.elementwise`)."""
    x, y, z, w = q
    flip = w < 0.0
    if flip is True or flip is not False and any_(flip):  # one value tested inline: elementwise
        if flip is True or all_(flip):
            x, y, z, w = -x, -y, -z, -w
        else:
            x, y, z, w = (
                where(flip, -x, x),
                where(flip, -y, y),
                where(flip, -z, z),
                where(flip, -w, w),
            )
    vnorm = sqrt(x * x + y * y + z * z)
    small = vnorm < 1e-12
    if small is False or small is not True and not any_(small):
        scale = 2.0 * atan2(vnorm, w) / vnorm
    elif small is True or all_(small):
        scale = 2.0 / w
    else:
        scale = where(small, 2.0 / w, 2.0 * atan2(vnorm, w) / vnorm)
    return (x * scale, y * scale, z * scale)


def unwrap_rotvec(principal: Sequence[Any], reference: Sequence[Any]) -> tuple[Any, Any, Any]:
    """The rotation vector of the same rotation that lies closest to ``reference`` (the one
    unwrap of the project: env deviations, the batched env's, planner, expert and comparison
    controllers; elementwise on arrays of components as well).

    Same rotation = axis * (angle + 2 pi k) for any integer k (the family along ``-axis`` is
    the same set), so a tracked deviation phi stays continuous across steps and a
    somersault's |phi| can exceed pi. For the identity the axis is taken from ``reference``.
    """
    px, py, pz = principal
    rx, ry, rz = reference
    angle = sqrt(px * px + py * py + pz * pz)
    small = angle < 1e-12
    keep = small
    if small is True or small is not False and any_(small):
        rn = sqrt(rx * rx + ry * ry + rz * rz)
        keep = small & (rn < math.pi)
        if all_(keep):
            return (px, py, pz)
        if all_(small):
            ux, uy, uz = rx / rn, ry / rn, rz / rn
        else:
            ux, uy, uz = where3(
                small, (rx / rn, ry / rn, rz / rn), (px / angle, py / angle, pz / angle)
            )
    else:
        ux, uy, uz = px / angle, py / angle, pz / angle
    k = rint((ux * rx + uy * ry + uz * rz - angle) / TWO_PI)
    keep = keep | (k == 0)
    if keep is True or keep is not False and all_(keep):
        return (px, py, pz)
    a = angle + TWO_PI * k
    if keep is False or not any_(keep):
        return (ux * a, uy * a, uz * a)
    return where3(keep, (px, py, pz), (ux * a, uy * a, uz * a))


def rotate(q: Sequence[float], v: Sequence[float]) -> Vec3:
    """``R(q) v`` without building a matrix."""
    x, y, z, w = q
    vx, vy, vz = v
    tx = 2.0 * (y * vz - z * vy)
    ty = 2.0 * (z * vx - x * vz)
    tz = 2.0 * (x * vy - y * vx)
    return (
        vx + w * tx + (y * tz - z * ty),
        vy + w * ty + (z * tx - x * tz),
        vz + w * tz + (x * ty - y * tx),
    )


def rotate_back(q: Sequence[float], v: Sequence[float]) -> Vec3:
    """``R(q)^T v``: ``v`` from the world into the frame of a unit quaternion ``q``."""
    return rotate((-q[0], -q[1], -q[2], q[3]), v)


def to_matrix(q: Sequence[float]) -> tuple[Vec3, Vec3, Vec3]:
    """Rotation matrix of ``q`` as three row tuples."""
    x, y, z, w = q
    return (
        (1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)),
        (2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)),
        (2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)),
    )
