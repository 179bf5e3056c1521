"""Elementwise numpy twins of the env's per-body float arithmetic, for the batched task.

Each function repeats one scalar helper (:mod:`sgc_env.paper.quaternion`, the reward costs of
:mod:`sgc_env.envs.rewards`) on arrays of any shape, operation for operation in the scalar
code's order (numpy evaluates ``a + b * c + d`` as Python does: no reordering, no fused
multiply-add), so each element equals the scalar result bit for bit. ``atan2``, the one
transcendental function, goes through ``math.atan2`` per element: numpy's SIMD versions may
differ from libm's in the last bit. Branches become ``np.where`` over both sides (callers
silence the warnings of the side not taken with ``np.errstate``).
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["at_most", "atan2", "log", "mul_conjugate", "norm3", "rotate", "unwrap_rotvec"]

Arr = np.ndarray
TWO_PI = 2.0 * math.pi


def rotate(x: Arr, y: Arr, z: Arr, w: Arr, vx: Arr, vy: Arr, vz: Arr) -> tuple[Arr, Arr, Arr]:
    """:func:`sgc_env.paper.quaternion.rotate` per element."""
    tx = 2.0 * (y * vz - z * vy)
    ty = 2.0 * (z * vx - x * vz)
    tz = 2.0 * (x * vy - y * vx)
    return (
        vx + w * tx + (y * tz - z * ty),
        vy + w * ty + (z * tx - x * tz),
        vz + w * tz + (x * ty - y * tx),
    )


def mul_conjugate(a: Arr, b: Arr) -> tuple[Arr, Arr, Arr, Arr]:
    """:func:`sgc_env.paper.quaternion.mul_conjugate` on (..., 4) arrays, as components."""
    ax, ay, az, aw = a[..., 0], a[..., 1], a[..., 2], a[..., 3]
    bx, by, bz, bw = b[..., 0], b[..., 1], b[..., 2], b[..., 3]
    return (
        -aw * bx + ax * bw - ay * bz + az * by,
        -aw * by + ax * bz + ay * bw - az * bx,
        -aw * bz - ax * by + ay * bx + az * bw,
        aw * bw + ax * bx + ay * by + az * bz,
    )


def atan2(y: Arr, x: Arr) -> Arr:
    """``math.atan2`` per element (libm's, as the scalar code)."""
    out = list(map(math.atan2, y.ravel().tolist(), x.ravel().tolist()))
    return np.array(out, dtype=np.float64).reshape(y.shape)


def norm3(x: Arr, y: Arr, z: Arr) -> Arr:
    """``math.sqrt(x * x + y * y + z * z)`` (sqrt is correctly rounded in both)."""
    return np.sqrt(x * x + y * y + z * z)


def log(x: Arr, y: Arr, z: Arr, w: Arr) -> tuple[Arr, Arr, Arr]:
    """:func:`sgc_env.paper.quaternion.log` per element."""
    flip = w < 0.0
    x, y, z, w = (np.where(flip, -c, c) for c in (x, y, z, w))
    vnorm = norm3(x, y, z)
    scale = np.where(vnorm < 1e-12, 2.0 / w, 2.0 * atan2(vnorm, w) / vnorm)
    return x * scale, y * scale, z * scale


def unwrap_rotvec(
    px: Arr, py: Arr, pz: Arr, rx: Arr, ry: Arr, rz: Arr
) -> tuple[Arr, Arr, Arr]:
    """:func:`sgc_env.paper.quaternion.unwrap_rotvec` per element (``round`` is half to even,
    as ``np.rint``)."""
    angle = norm3(px, py, pz)
    tiny = angle < 1e-12
    rn = norm3(rx, ry, rz)
    keep = tiny & (rn < math.pi)
    ux = np.where(tiny, rx / rn, px / angle)
    uy = np.where(tiny, ry / rn, py / angle)
    uz = np.where(tiny, rz / rn, pz / angle)
    s = ux * rx + uy * ry + uz * rz
    k = np.rint((s - angle) / TWO_PI)
    keep |= k == 0
    a = angle + TWO_PI * k
    return np.where(keep, px, ux * a), np.where(keep, py, uy * a), np.where(keep, pz, uz * a)


def at_most(value: Arr, cap: float) -> Arr:
    """Python's ``min(value, cap)``: ``value`` unless ``cap < value`` (NaN stays NaN)."""
    return np.where(cap < value, cap, value)


def at_least(value: Arr, floor: float) -> Arr:
    """Python's ``max(value, floor)``: ``value`` unless ``floor > value``."""
    return np.where(floor > value, floor, value)
