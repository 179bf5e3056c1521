"""Numpy twins of the env's per-body float helpers, for the batched task.

Each function repeats one scalar helper (:mod:`sgc_env.paper.quaternion`, Python's
``min``/``max``) on arrays of vectors (last axis xyz or xyzw), operation for operation in the
scalar code's order: numpy evaluates ``a + b * c + d`` as Python does (no reordering, no fused
multiply-add) and the components of a cross product come from one gather each, so every
element equals the scalar result bit for bit (tests/sgc_env/envs/test_batch_math.py). Rewrites used,
all exact in IEEE arithmetic: ``-a * b == a * (-b)``, ``x - y == x + (-y)``, and a product times
-1 is its negation. ``atan2``, the one transcendental function, goes through ``math.atan2``
per element: numpy's SIMD versions may differ from libm's in the last bit. Branches become
``np.where`` over both sides, skipped where every element takes the same one (callers silence
the warnings of a side not taken with ``np.errstate``).
"""

from __future__ import annotations

import math

import numpy as np

__all__ = [
    "at_least", "at_most", "atan2", "conjugate_factors", "log", "mul_conjugate", "norm",
    "norm3", "rotate", "unwrap_rotvec",
]  # fmt: skip

Arr = np.ndarray
TWO_PI = 2.0 * math.pi
_YZX, _ZXY = [1, 2, 0], [2, 0, 1]
# a * conj(b), component c = sum_k sign[k][c] * a[(w, x, y, z)[k]] * b[perm[k][c]], summed in the
# order of quaternion.mul_conjugate's terms
_PERMS = ([0, 1, 2, 3], [3, 2, 1, 0], [2, 3, 0, 1], [1, 0, 3, 2])
_SIGNS = np.array(((-1, -1, -1, 1), (1, 1, -1, 1), (-1, 1, 1, 1), (1, -1, 1, 1)), dtype=float)


def rotate(q: Arr, v: Arr) -> Arr:
    """:func:`sgc_env.paper.quaternion.rotate` on (..., 4) quaternions and (..., 3) vectors."""
    u, w = q[..., 0:3], q[..., 3:4]
    uy, uz = u[..., _YZX], u[..., _ZXY]
    t = 2.0 * (uy * v[..., _ZXY] - uz * v[..., _YZX])
    return v + w * t + (uy * t[..., _ZXY] - uz * t[..., _YZX])


def conjugate_factors(b: Arr) -> list[Arr]:
    """The four signed permutations of quaternions ``b`` that :func:`mul_conjugate` takes
    (computed once per goal: ``b`` is the goal orientation)."""
    return [b[..., perm] * sign for perm, sign in zip(_PERMS, _SIGNS, strict=True)]


def mul_conjugate(a: Arr, factors: list[Arr]) -> Arr:
    """:func:`sgc_env.paper.quaternion.mul_conjugate` of (..., 4) quaternions ``a`` and the
    :func:`conjugate_factors` of ``b``."""
    f1, f2, f3, f4 = factors
    return a[..., 3:4] * f1 + a[..., 0:1] * f2 + a[..., 1:2] * f3 + a[..., 2:3] * f4


def norm(v: Arr) -> Arr:
    """``math.sqrt(x * x + y * y + z * z)`` over the last axis (sqrt is correctly rounded)."""
    sq = v * v
    return np.sqrt(sq[..., 0] + sq[..., 1] + sq[..., 2])


def atan2(y: Arr, x: Arr) -> Arr:
    """``math.atan2`` per element (libm's, as the scalar code)."""
    out = list(map(math.atan2, y.ravel().tolist(), x.ravel().tolist()))
    return np.array(out, dtype=np.float64).reshape(y.shape)


def norm3(x: Arr, y: Arr, z: Arr) -> Arr:
    """``math.sqrt(x * x + y * y + z * z)`` (sqrt is correctly rounded in both)."""
    return np.sqrt(x * x + y * y + z * z)


def log(q: Arr) -> Arr:
    """:func:`sgc_env.paper.quaternion.log` of (..., 4) quaternions."""
    v, w = q[..., 0:3], q[..., 3]
    flip = w < 0.0
    if flip.any():
        v, w = np.where(flip[..., None], -v, v), np.where(flip, -w, w)
    vnorm = norm(v)
    scale = 2.0 * atan2(vnorm, w) / vnorm
    small = vnorm < 1e-12
    if small.any():
        scale = np.where(small, 2.0 / w, scale)
    return v * scale[..., None]


def unwrap_rotvec(p: Arr, r: Arr) -> Arr:
    """:func:`sgc_env.paper.quaternion.unwrap_rotvec` of (..., 3) rotation vectors ``p`` with
    references ``r`` (``round`` is half to even, as ``np.rint``)."""
    angle = norm(p)
    keep = angle < 1e-12
    if keep.any():
        rn = norm(r)
        u = np.where(keep[..., None], r / rn[..., None], p / angle[..., None])
        keep &= rn < math.pi
    else:
        u = p / angle[..., None]
    su = u * r
    k = np.rint((su[..., 0] + su[..., 1] + su[..., 2] - angle) / TWO_PI)
    keep |= k == 0
    if keep.all():
        return p
    return np.where(keep[..., None], p, u * (angle + TWO_PI * k)[..., None])


def at_most(value: Arr, cap: float) -> Arr:
    """Python's ``min(value, cap)``: ``value`` unless ``cap < value`` (NaN stays NaN)."""
    return np.where(cap < value, cap, value)


def at_least(value: Arr, floor: float) -> Arr:
    """Python's ``max(value, floor)``: ``value`` unless ``floor > value``."""
    return np.where(floor > value, floor, value)
