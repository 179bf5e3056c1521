"""One scalar component of one SGC course (Liu, Ko & Chang 1993, eqs. 5-9, corrected).

The behaviour equation ``D'' - 2a D' + (a^2 + b^2) D = 0`` with ``D(0) = d0``,
``D'(0) = v0``, ``D(T) = 0`` and ``D'(T) = -k d0 / T`` reduces (method notes) to one equation
in ``z = (bT)^2`` that depends on the data only through ``y = gamma T - log k``
(``gamma = v0 / d0``)::

    phi(z) := log S(z) - C(z) / S(z) = y,        aT = log(k S(z))

``phi`` is strictly increasing on ``z < pi^2`` from ``-inf`` to ``+inf``, so every finite
``y`` has one root: ``z > 0`` (oscillatory, the paper's case), ``z = 0`` (critical) or
``z < 0`` (overdamped, the sinh continuation). ``D`` keeps the sign of ``d0`` on ``[0, T)``.

Numerics. Newton runs on a transformed variable ``xi`` in which ``phi`` is nearly the
identity shifted by -1 (slope between 1 and 1.22), so 2-4 steps reach machine precision from
the guess ``xi = y + 1``:

* overdamped, ``w = sqrt(-z)``: ``xi = -log(1 + w^2 / 3) / 2`` and
  ``phi = log h(2w) - exp(-2w) / h(2w)`` with ``h(x) = -expm1(-x) / x``;
* oscillatory, ``s = sqrt(z)``: ``xi = (pi^2 / 6) s^2 / (pi^2 - s^2)``, with ``p = pi - s``
  kept separately so that ``sin s`` stays accurate near ``s = pi``.

The profile is evaluated in forms that never overflow for large ``|aT|``: for ``z <= 0``,
``D = d0 exp(m tau) u h(2 w u) / h(2 w)`` with ``m = aT - w = log k + log h(2w) <= log k``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import cast

import numpy as np
from numpy.typing import ArrayLike

from sgc_env.paper.hermite import Evaluated, HermiteProfile, HoldProfile

Num = float | np.ndarray
Floats3 = tuple[float, float, float]
Arrays3 = tuple[np.ndarray, np.ndarray, np.ndarray]
"""A float or an array of them (the profiles evaluate either elementwise)."""

__all__ = [
    "BRANCH_CODES",
    "CRITICAL_TOLERANCE",
    "CourseBatch",
    "CourseProfile",
    "HoldProfile",
    "HermiteProfile",
    "solve_batch",
]

_PI = math.pi
_HALF_PI = 0.5 * math.pi
_A = _PI * _PI / 6.0  # scale of the oscillatory variable xi (slope 1 at xi = 0)
CRITICAL_TOLERANCE = 1e-12
"""``|z| = |bT|^2`` below which a course is labelled ``"critical"`` (evaluation is smooth)."""
Y_MIN = -350.0
"""Smallest ``gamma T - log k`` accepted: below it ``beta^2`` would overflow a float."""
Y_MAX = 1e12
"""Largest ``gamma T - log k`` accepted: above it ``pi - bT`` (about ``pi / y``) underflows."""
BRANCH_CODES = {"overdamped": -1, "critical": 0, "oscillatory": 1}
_BRANCH_NAMES = {v: k for k, v in BRANCH_CODES.items()}
_SQRT3 = math.sqrt(3.0)
_isfinite = math.isfinite
_STEP_TOL_TABLE = 1e-7  # Newton stops after a step this small: the next error is ~step^2/10


def _check_inputs(d0: float, v0: float, duration: float, k: float) -> None:
    for name, value in (("d0", d0), ("v0", v0), ("duration", duration), ("k", k)):
        if not math.isfinite(value):
            raise ValueError(f"{name} must be finite, got {value!r}")
    if d0 == 0.0:
        raise ValueError(
            "d0 must be nonzero: a course that starts on its goal is a dwell, handled at plan "
            "level (HoldProfile / HermiteProfile), not by the SGC family"
        )
    if duration <= 0.0:
        raise ValueError(f"duration must be > 0, got {duration!r}")
    if k <= 0.0:
        raise ValueError(
            f"k must be > 0, got {k!r}: the end velocity must point at the goal; the frame "
            "rules clamp k to k_min > 0 at plan level"
        )


def _range_message(y: float) -> str:
    if y < Y_MIN:
        return (
            f"gamma*T - log k = {y!r} is below {Y_MIN}: the course starts moving towards its "
            "goal too fast for a representable overdamped profile"
        )
    return (
        f"gamma*T - log k = {y!r} is above {Y_MAX:g}: the course starts moving away from its "
        "goal too fast for a representable profile"
    )


def _over_eval(xi: float) -> tuple[float, float, float]:
    """Overdamped side: (phi, dphi/dxi, w) at ``xi <= 0``."""
    if xi > -150.0:
        w = math.sqrt(3.0 * math.expm1(-2.0 * xi))
    else:
        w = math.sqrt(3.0) * math.exp(-xi)
    if w < 1e-4:
        w2 = w * w
        return -1.0 - w2 / 6.0, 1.0 + 2.0 * w2 / 15.0, w
    e = math.exp(-2.0 * w)
    h = -math.expm1(-2.0 * w) / (2.0 * w)
    phi = math.log(h) - e / h
    # dphi/dw = (e/h^2 - 1)/w and dw/dxi = -3 exp(-2 xi)/w = -(3 + w^2)/w
    r = w / math.sinh(w) if w < 20.0 else 2.0 * w * math.exp(-w)
    slope = (1.0 - r * r) * (3.0 + w * w) / (w * w)
    return phi, slope, w


def _osc_eval(xi: float) -> tuple[float, float, float, float]:
    """Oscillatory side: (phi, dphi/dxi, s, p) at ``xi >= 0`` with ``p = pi - s``."""
    frac = xi / (_A + xi)
    root = math.sqrt(frac)
    s = _PI * root
    p = _PI * (_A / (_A + xi)) / (1.0 + root)
    if s < 1e-4:
        s2 = s * s
        return -1.0 + s2 / 6.0 + s2 * s2 / 60.0, 1.0, s, p
    if s < 1.5:
        sin_s, cos_s = math.sin(s), math.cos(s)
    else:
        sin_s, cos_s = math.sin(p), -math.cos(p)
    ratio = sin_s / s
    phi = math.log(ratio) - s * cos_s / sin_s
    dphi_ds = (1.0 - ratio * ratio) / (s * ratio * ratio)
    ds_dxi = _PI * _PI * _A / (2.0 * s * (_A + xi) ** 2)
    return phi, dphi_ds * ds_dxi, s, p


def _newton_xi(y: float, xi: float, lo: float, hi: float, tol: float) -> float:
    """Safeguarded Newton on ``phi(xi) = y`` inside the bracket ``[lo, hi]``."""
    evaluate = _over_eval if y <= -1.0 else _osc_eval
    for _ in range(200):
        f, slope = evaluate(xi)[:2]
        f -= y
        if f > 0.0:
            hi = xi
        elif f < 0.0:
            lo = xi
        else:
            return xi
        new = xi - f / slope
        if not lo <= new <= hi:
            new = 0.5 * (lo + hi)
        if abs(new - xi) <= tol * (1.0 + abs(xi)):
            return new
        xi = new
    return xi


def _bracket(y: float) -> tuple[float, float]:
    """Bracket of the root from the slope bounds of ``phi`` in ``xi`` (checked in tests)."""
    if y <= -1.0:
        return y + 1.0, min(0.0, y + 1.25)
    return (y + 1.0) / 1.22, (y + 1.0) / 0.998


def _guess(y: float) -> float:
    t = y + 1.0
    if y <= -1.0:
        return t + 0.243 * (1.0 - math.exp(0.6 * t))
    return t / (1.0 + 0.216 * t / (t + 3.0))


def _solve_xi_plain(y: float) -> float:
    lo, hi = _bracket(y)
    return _newton_xi(y, _guess(y), lo, hi, 1e-9)


# Cubic Hermite table of the inverse xi(y) on [_Y0, _Y1] with a node at y = -1 (where the
# second derivative jumps). From it one Newton step reaches machine precision.
_H = 0.05
_Y0 = -1.0 - 30.0
_N = 1600
_Y1 = _Y0 + _N * _H
_TAB_XI = [_solve_xi_plain(_Y0 + i * _H) for i in range(_N + 1)]
_TAB_DXI = [
    1.0 / (_over_eval(x)[1] if x <= 0.0 else _osc_eval(x)[1]) for x in _TAB_XI
]
_TAB_XI_NP = np.array(_TAB_XI)
_TAB_DXI_NP = np.array(_TAB_DXI)


def _solve_xi(y: float) -> float:
    """Root ``xi`` of ``phi(xi) = y``: table guess, then safeguarded Newton."""
    if _Y0 <= y < _Y1:
        q = (y - _Y0) / _H
        i = min(int(q), _N - 1)  # y just below _Y1 can round to q == _N, as in _solve_xi_vec
        r = q - i
        x0, x1 = _TAB_XI[i], _TAB_XI[i + 1]
        m0, m1 = _TAB_DXI[i] * _H, _TAB_DXI[i + 1] * _H
        r2 = r * r
        r3 = r2 * r
        xi = (
            (2.0 * r3 - 3.0 * r2 + 1.0) * x0
            + (r3 - 2.0 * r2 + r) * m0
            + (3.0 * r2 - 2.0 * r3) * x1
            + (r3 - r2) * m1
        )
        lo, hi = _bracket(y)
        return _newton_xi(y, min(max(xi, lo), hi), lo, hi, _STEP_TOL_TABLE)
    return _solve_xi_plain(y)


class CourseProfile(Evaluated):
    """Closed-form SGC profile of one component: ``D(t)`` on ``[0, T]``.

    Build it with :meth:`solve`; treat it as immutable. ``alpha = a`` and
    ``beta_squared = b^2`` are the gains of the behaviour equation (``beta_squared < 0`` on the
    overdamped branch). Times passed to :meth:`position` etc. are seconds from the course
    start; values outside ``[0, T]`` are the analytic continuation (no clamping). A plain
    ``__slots__`` class rather than a frozen dataclass: construction is on the expert's
    per-step hot path.
    """

    __slots__ = (
        "d0", "v0", "duration", "k", "alpha", "beta_squared", "branch", "z", "_w", "_s", "_p",
        "_m",
    )

    def __init__(
        self, d0: float, v0: float, duration: float, k: float, alpha: float,
        beta_squared: float, branch: str, z: float, w: float, s: float, p: float, m: float,
    ) -> None:  # fmt: skip
        self.d0 = d0
        self.v0 = v0
        self.duration = duration
        self.k = k
        self.alpha = alpha
        self.beta_squared = beta_squared
        self.branch = branch
        self.z = z  # (bT)^2, the dimensionless root
        self._w = w  # sqrt(-z) for z <= 0, else 0
        self._s = s  # sqrt(z) for z > 0, else 0
        self._p = p  # pi - s, accurate near pi
        self._m = m  # aT - w for z <= 0, aT for z > 0

    def __repr__(self) -> str:
        return (
            f"CourseProfile(d0={self.d0!r}, v0={self.v0!r}, duration={self.duration!r}, "
            f"k={self.k!r}, alpha={self.alpha!r}, beta_squared={self.beta_squared!r}, "
            f"branch={self.branch!r})"
        )

    @classmethod
    def solve(cls, d0: float, v0: float, duration: float, k: float) -> CourseProfile:
        """Solve the course for ``D(0)=d0, D'(0)=v0, D(T)=0, D'(T)=-k d0/T``.

        Raises ValueError for non-finite input, ``d0 == 0`` (a dwell: plan level),
        ``duration <= 0``, ``k <= 0`` (clamped at plan level by the frame rules), and for
        ``gamma T - log k`` outside ``[-350, 1e12]`` (beyond it ``b^2`` overflows, or
        ``pi - bT`` underflows, a float).
        """
        d0, v0, duration, k = float(d0), float(v0), float(duration), float(k)
        if not (d0 != 0.0 and duration > 0.0 and k > 0.0 and _isfinite(d0 + v0 + duration + k)):
            _check_inputs(d0, v0, duration, k)
        log_k = math.log(k)
        y = v0 * duration / d0 - log_k
        if not Y_MIN <= y <= Y_MAX:
            raise ValueError(_range_message(y))
        xi = _solve_xi(y)
        if xi <= 0.0:
            w = math.sqrt(3.0 * math.expm1(-2.0 * xi)) if xi > -150.0 else _SQRT3 * math.exp(-xi)
            if w > 0.0:
                m = log_k + math.log(-math.expm1(-2.0 * w) / (2.0 * w))
            else:
                m = log_k
            z = -w * w
            big_a, s, p = m + w, 0.0, _PI
        else:
            root = math.sqrt(xi / (_A + xi))
            s = _PI * root
            p = _PI * (_A / (_A + xi)) / (1.0 + root)
            w = 0.0
            big_a = m = log_k + math.log((math.sin(s) if s < 1.5 else math.sin(p)) / s)
            z = s * s
        if z > CRITICAL_TOLERANCE:
            branch = "oscillatory"
        elif z < -CRITICAL_TOLERANCE:
            branch = "overdamped"
        else:
            branch = "critical"
        return cls(
            d0, v0, duration, k, big_a / duration, z / (duration * duration), branch, z,
            w, s, p, m,
        )

    def evaluate(self, t: float | np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(D, D', D'')`` at ``t`` (seconds from course start), each shaped like ``t``."""
        t_arr = np.asarray(t, dtype=float)
        T = self.duration
        tau = t_arr / T
        u = 1.0 - tau
        if self._s > 0.0:
            d, v, a = _osc_profile(self._m, self._s, self._p, tau, u)
        else:
            d, v, a = _over_profile(self._m, self._w, tau, u)
        return cast(Arrays3, (self.d0 * d, self.d0 * v / T, self.d0 * a / (T * T)))

    def state(self, t: float) -> tuple[float, float, float]:
        """Scalar fast path: ``(D, D', D'')`` at a scalar ``t`` using the math module."""
        T = self.duration
        tau = t / T
        u = 1.0 - tau
        if self._s > 0.0:
            s, p, big_a = self._s, self._p, self._m
            pre = math.exp(big_a * tau) / (math.sin(s) if s < 1.5 else math.sin(p))
            su = s * u
            if su < _HALF_PI:  # exact zero at u = 0
                sn, cs = math.sin(su), math.cos(su)
            else:  # sin(s u) = sin(pi tau + p u): accurate when s u is close to pi
                arg = _PI * tau + p * u
                sn, cs = math.sin(arg), -math.cos(arg)
            d = pre * sn
            v = pre * (big_a * sn - s * cs)
            a = pre * ((big_a * big_a - s * s) * sn - 2.0 * big_a * s * cs)
        else:
            w, m = self._w, self._m
            e_m = math.exp(m * tau)
            if w > 0.0:
                inv_h = 2.0 * w / -math.expm1(-2.0 * w)
                big_h = -math.expm1(-2.0 * w * u) / (2.0 * w)
                e_u = math.exp(-2.0 * w * u)
            else:
                inv_h, big_h, e_u = 1.0, u, 1.0
            pre = e_m * inv_h
            d = pre * big_h
            v = pre * (m * big_h - e_u)
            a = pre * (m * m * big_h - 2.0 * (m + w) * e_u)
        d0 = self.d0
        return d0 * d, d0 * v / T, d0 * a / (T * T)


def _osc_profile(big_a: Num, s: Num, p: Num, tau: Num, u: Num) -> tuple[Num, Num, Num]:
    """Normalised ``(D, dD/dtau, d2D/dtau2) / d0`` on the oscillatory branch (arrays ok)."""
    pre = np.exp(big_a * tau) / np.where(s < 1.5, np.sin(s), np.sin(p))
    su = s * u
    low = su < _HALF_PI  # direct form: exact zero at u = 0
    arg = np.pi * tau + p * u  # = pi - s u: sin(s u) = sin(arg) stays accurate near s u = pi
    sn = np.where(low, np.sin(su), np.sin(arg))
    cs = np.where(low, np.cos(su), -np.cos(arg))
    return (
        pre * sn,
        pre * (big_a * sn - s * cs),
        pre * ((big_a * big_a - s * s) * sn - 2.0 * big_a * s * cs),
    )


def _over_profile(m: Num, w: Num, tau: Num, u: Num) -> tuple[Num, Num, Num]:
    """Normalised ``(D, dD/dtau, d2D/dtau2) / d0`` for ``z <= 0`` (arrays ok)."""
    two_w = 2.0 * np.asarray(w, dtype=float)
    safe = np.where(two_w > 0.0, two_w, 1.0)
    inv_h = np.where(two_w > 0.0, safe / -np.expm1(-safe), 1.0)
    x = two_w * u
    big_h = np.where(two_w > 0.0, -np.expm1(-x) / safe, u)
    e_u = np.exp(-x)
    pre = np.exp(m * tau) * inv_h
    return (
        pre * big_h,
        pre * (m * big_h - e_u),
        pre * (m * m * big_h - 2.0 * (m + 0.5 * two_w) * e_u),
    )


@dataclass(frozen=True)
class CourseBatch:
    """Many independent course components solved together (see :func:`solve_batch`).

    All arrays have the broadcast shape of the inputs. ``branch`` holds codes from
    ``BRANCH_CODES`` (-1 overdamped, 0 critical, 1 oscillatory).
    """

    d0: np.ndarray
    v0: np.ndarray
    duration: np.ndarray
    k: np.ndarray
    alpha: np.ndarray
    beta_squared: np.ndarray
    branch: np.ndarray
    _w: np.ndarray
    _s: np.ndarray
    _p: np.ndarray
    _m: np.ndarray

    def evaluate(self, t: float | np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(D, D', D'')`` of every component at times ``t`` (broadcast against the batch)."""
        T = self.duration
        tau = np.asarray(t, dtype=float) / T
        u = 1.0 - tau
        osc = self._s > 0.0
        d_o, v_o, a_o = _osc_profile(self._m, np.where(osc, self._s, 1.0), self._p, tau, u)
        d_c, v_c, a_c = _over_profile(self._m, self._w, tau, u)
        d = np.where(osc, d_o, d_c)
        v = np.where(osc, v_o, v_c)
        a = np.where(osc, a_o, a_c)
        return self.d0 * d, self.d0 * v / T, self.d0 * a / (T * T)

    def position(self, t: float | np.ndarray) -> np.ndarray:
        return self.evaluate(t)[0]

    def velocity(self, t: float | np.ndarray) -> np.ndarray:
        return self.evaluate(t)[1]

    def acceleration(self, t: float | np.ndarray) -> np.ndarray:
        return self.evaluate(t)[2]

    def branch_names(self) -> np.ndarray:
        """Branch labels as strings."""
        return np.vectorize(_BRANCH_NAMES.__getitem__, otypes=[object])(self.branch)


def _over_eval_vec(xi: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    xi_c = np.minimum(xi, 0.0)
    w = np.where(
        xi_c > -150.0,
        np.sqrt(3.0 * np.expm1(-2.0 * np.maximum(xi_c, -150.0))),
        np.sqrt(3.0) * np.exp(-np.maximum(xi_c, -400.0)),
    )
    small = w < 1e-4
    ws = np.where(small, 1.0, w)
    e = np.exp(-2.0 * ws)
    h = -np.expm1(-2.0 * ws) / (2.0 * ws)
    phi = np.log(h) - e / h
    r = np.where(ws < 20.0, ws / np.sinh(np.minimum(ws, 20.0)), 2.0 * ws * np.exp(-ws))
    slope = (1.0 - r * r) * (3.0 + ws * ws) / (ws * ws)
    w2 = w * w
    phi = np.where(small, -1.0 - w2 / 6.0, phi)
    slope = np.where(small, 1.0 + 2.0 * w2 / 15.0, slope)
    return phi, slope, w


def _osc_eval_vec(xi: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    xi_c = np.maximum(xi, 0.0)
    frac = xi_c / (_A + xi_c)
    root = np.sqrt(frac)
    s = _PI * root
    p = _PI * (_A / (_A + xi_c)) / (1.0 + root)
    small = s < 1e-4
    ss = np.where(small, 1.0, s)
    low = ss < 1.5
    sin_s = np.where(low, np.sin(ss), np.sin(p))
    cos_s = np.where(low, np.cos(ss), -np.cos(p))
    ratio = sin_s / ss
    phi = np.log(ratio) - ss * cos_s / sin_s
    dphi_ds = (1.0 - ratio * ratio) / (ss * ratio * ratio)
    slope = dphi_ds * _PI * _PI * _A / (2.0 * ss * (_A + xi_c) ** 2)
    s2 = s * s
    phi = np.where(small, -1.0 + s2 / 6.0 + s2 * s2 / 60.0, phi)
    slope = np.where(small, 1.0, slope)
    return phi, slope, s, p


def _solve_xi_vec(y: np.ndarray) -> np.ndarray:
    over = y <= -1.0
    t = y + 1.0
    lo = np.where(over, t, t / 1.22)
    hi = np.where(over, np.minimum(0.0, y + 1.25), t / 0.998)
    xi = np.where(
        over,
        t + 0.243 * (1.0 - np.exp(0.6 * np.minimum(t, 0.0))),
        t / (1.0 + 0.216 * np.maximum(t, 0.0) / (np.abs(t) + 3.0)),
    )
    in_table = (y >= _Y0) & (y < _Y1)
    q = np.where(in_table, (y - _Y0) / _H, 0.0)
    i = np.minimum(q.astype(np.intp), _N - 1)
    r = q - i
    r2 = r * r
    r3 = r2 * r
    table = (
        (2.0 * r3 - 3.0 * r2 + 1.0) * _TAB_XI_NP[i]
        + (r3 - 2.0 * r2 + r) * _TAB_DXI_NP[i] * _H
        + (3.0 * r2 - 2.0 * r3) * _TAB_XI_NP[i + 1]
        + (r3 - r2) * _TAB_DXI_NP[i + 1] * _H
    )
    xi = np.clip(np.where(in_table, table, xi), lo, hi)
    active = np.ones(y.shape, dtype=bool)
    for _ in range(100):
        f_o, sl_o = _over_eval_vec(xi)[:2]
        f_s, sl_s = _osc_eval_vec(xi)[:2]
        f = np.where(over, f_o, f_s) - y
        slope = np.where(over, sl_o, sl_s)
        hi = np.where(f > 0.0, xi, hi)
        lo = np.where(f < 0.0, xi, lo)
        new = xi - f / slope
        new = np.where((new >= lo) & (new <= hi), new, 0.5 * (lo + hi))
        new = np.where(f == 0.0, xi, new)
        done = np.abs(new - xi) <= _STEP_TOL_TABLE * (1.0 + np.abs(xi))
        xi = np.where(active, new, xi)
        active &= ~done
        if not active.any():
            break
    return xi


def solve_batch(d0: ArrayLike, v0: ArrayLike, duration: ArrayLike, k: ArrayLike) -> CourseBatch:
    """Vectorised :meth:`CourseProfile.solve` over broadcastable arrays.

    Same validation and the same root (to rounding) as the scalar solver; a ValueError names
    the argument and the flat index of the first bad element.
    """
    d0, v0, duration, k = np.broadcast_arrays(
        *(np.asarray(x, dtype=float) for x in (d0, v0, duration, k))
    )
    for name, arr in (("d0", d0), ("v0", v0), ("duration", duration), ("k", k)):
        bad = ~np.isfinite(arr)
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            raise ValueError(f"{name}[{i}] must be finite, got {arr.flat[i]!r}")
    for name, arr, ok, what in (
        ("d0", d0, d0 != 0.0, "nonzero (a dwell is handled at plan level)"),
        ("duration", duration, duration > 0.0, "> 0"),
        ("k", k, k > 0.0, "> 0 (clamped to k_min at plan level)"),
    ):
        if not ok.all():
            i = int(np.flatnonzero(~ok)[0])
            raise ValueError(f"{name}[{i}] must be {what}, got {arr.flat[i]!r}")
    log_k = np.log(k)
    y = v0 * duration / d0 - log_k
    ok = (y >= Y_MIN) & (y <= Y_MAX)
    if not ok.all():
        i = int(np.flatnonzero(~ok)[0])
        raise ValueError(f"element {i}: {_range_message(float(y.flat[i]))}")
    xi = _solve_xi_vec(y)
    over = xi <= 0.0
    w = np.where(over, _over_eval_vec(xi)[2], 0.0)
    _, _, s, p = _osc_eval_vec(xi)
    s = np.where(over, 0.0, s)
    p = np.where(over, _PI, p)
    two_w = np.where(w > 0.0, 2.0 * w, 1.0)
    h = np.where(w > 0.0, -np.expm1(-two_w) / two_w, 1.0)
    s_safe = np.where(over, 1.0, s)
    sin_s = np.where(s_safe < 1.5, np.sin(s_safe), np.sin(p))
    m = np.where(over, log_k + np.log(h), log_k + np.log(sin_s / s_safe))
    big_a = np.where(over, m + w, m)
    z = np.where(over, -w * w, s * s)
    branch = np.where(np.abs(z) <= CRITICAL_TOLERANCE, 0, np.where(z > 0.0, 1, -1))
    return CourseBatch(
        d0, v0, duration, k, big_a / duration, z / (duration * duration), branch, w, s, p, m
    )
