"""Elementwise numpy twins of the env's branching float helpers, for the batched task.

The branch-free helpers of :mod:`sgc_env.paper.quaternion` (``rotate``, ``mul_conjugate``) take
tuples of arrays as they are; the ones with branches (``log``, ``unwrap_rotvec``, Python's
``min``/``max``) are repeated here on arrays of any shape, operation for operation in the scalar
code's order (numpy evaluates ``a + b * c + d`` as Python does: no reordering, no fused
multiply-add), so each element equals the scalar result bit for bit. ``atan2``, the one
transcendental function, goes through ``math.atan2`` per element: numpy's SIMD versions may
differ from libm's in the last bit. Branches become ``np.where`` over both sides (callers
silence the warnings of the side not taken with ``np.errstate``).
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["at_least", "at_most", "atan2", "log", "norm3", "unwrap_rotvec"]

Arr = np.ndarray
TWO_PI = 2.0 * math.pi


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
    if flip.any():
        x, y, z, w = (np.where(flip, -c, c) for c in (x, y, z, w))
    vnorm = norm3(x, y, z)
    scale = 2.0 * atan2(vnorm, w) / vnorm
    small = vnorm < 1e-12
    if small.any():
        scale = np.where(small, 2.0 / w, scale)
    return x * scale, y * scale, z * scale


def unwrap_rotvec(px: Arr, py: Arr, pz: Arr, rx: Arr, ry: Arr, rz: Arr) -> tuple[Arr, Arr, Arr]:
    """:func:`sgc_env.paper.quaternion.unwrap_rotvec` per element (``round`` is half to even,
    as ``np.rint``)."""
    angle = norm3(px, py, pz)
    tiny = angle < 1e-12
    if tiny.any():
        rn = norm3(rx, ry, rz)
        keep = tiny & (rn < math.pi)
        ux = np.where(tiny, rx / rn, px / angle)
        uy = np.where(tiny, ry / rn, py / angle)
        uz = np.where(tiny, rz / rn, pz / angle)
    else:
        keep = tiny
        ux, uy, uz = px / angle, py / angle, pz / angle
    s = ux * rx + uy * ry + uz * rz
    k = np.rint((s - angle) / TWO_PI)
    keep |= k == 0
    if keep.all():
        return px, py, pz
    a = angle + TWO_PI * k
    return np.where(keep, px, ux * a), np.where(keep, py, uy * a), np.where(keep, pz, uz * a)


def at_most(value: Arr, cap: float) -> Arr:
    """Python's ``min(value, cap)``: ``value`` unless ``cap < value`` (NaN stays NaN)."""
    return np.where(cap < value, cap, value)


def at_least(value: Arr, floor: float) -> Arr:
    """Python's ``max(value, floor)``: ``value`` unless ``floor > value``."""
    return np.where(floor > value, floor, value)
