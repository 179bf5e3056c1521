"""Dynamic constraints (Barzel & Barr 1988) as a comparison baseline.

Every deviation component obeys the critically damped law D'' + (2/tau) D' + D/tau^2 = 0, so
D decays towards zero but never reaches it; a goal counts as met when |D| < eps and the next
goal starts from the state at that moment. This is the method whose pathology the paper's
Figure 1 shows: goals are met early or late, never exactly, and the body nearly stops at
each one. The same law applies unchanged to a rotation-vector deviation phi.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import brentq

FloatArray = NDArray[np.float64]


def _vector(value: ArrayLike, name: str) -> FloatArray:
    arr = np.atleast_1d(np.asarray(value, dtype=float))
    if arr.ndim != 1 or arr.size == 0:
        raise ValueError(f"{name} must be a non-empty vector, got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be finite (no NaN or inf)")
    return arr


def _positive(value: float, name: str) -> float:
    if not (math.isfinite(value) and value > 0.0):
        raise ValueError(f"{name} must be finite and positive, got {value}")
    return float(value)


def desired_acceleration(
    deviation: ArrayLike, deviation_velocity: ArrayLike, tau: float
) -> FloatArray:
    """The feedback law D'' = -(2/tau) D' - D/tau^2, per component (broadcasts)."""
    _positive(tau, "tau")
    d = np.asarray(deviation, dtype=float)
    v = np.asarray(deviation_velocity, dtype=float)
    if d.shape != v.shape:
        raise ValueError(
            f"deviation {d.shape} and deviation_velocity {v.shape} must have the same shape"
        )
    return -2.0 / tau * v - d / tau**2


def choose_tau(duration: float, distance: float, eps: float) -> float:
    """tau such that a course from rest at `distance` reaches |D| = eps after `duration`.

    From rest, |D(t)| = distance * (1 + t/tau) e^{-t/tau}; with x = duration/tau the rule
    solves (1 + x) e^{-x} = eps/distance by brentq (the left side falls from 1 to 0 on x > 0,
    so the root is unique). The continuous law then meets the goal exactly at the nominal
    time; a discrete simulation meets it within a step or so.
    """
    _positive(duration, "duration")
    _positive(distance, "distance")
    _positive(eps, "eps")
    if eps >= distance:
        raise ValueError(f"distance ({distance}) must exceed eps ({eps}): the goal is met already")
    ratio = eps / distance
    x_hi = 1.0
    while (1.0 + x_hi) * math.exp(-x_hi) > ratio:
        x_hi *= 2.0
    x = brentq(lambda s: (1.0 + s) * math.exp(-s) - ratio, 0.0, x_hi, xtol=1e-14, rtol=1e-14)
    return duration / x


@dataclass(frozen=True)
class DynamicConstraintsCourse:
    """Closed-form course D(t) = (d0 + (v0 + d0/tau) t) e^{-t/tau} from (D0, D0')."""

    d0: FloatArray
    v0: FloatArray
    tau: float

    def __init__(self, d0: ArrayLike, v0: ArrayLike, tau: float) -> None:
        d = _vector(d0, "d0")
        v = _vector(v0, "v0")
        if d.shape != v.shape:
            raise ValueError(f"d0 {d.shape} and v0 {v.shape} must have the same shape")
        object.__setattr__(self, "d0", d)
        object.__setattr__(self, "v0", v)
        object.__setattr__(self, "tau", _positive(tau, "tau"))

    @property
    def _c(self) -> FloatArray:
        return self.v0 + self.d0 / self.tau

    def _times(self, t: ArrayLike) -> FloatArray:
        ts = np.asarray(t, dtype=float)
        if not np.all(np.isfinite(ts)):
            raise ValueError("t must be finite")
        return ts[..., None]

    def position(self, t: ArrayLike) -> FloatArray:
        """D(t), shape t.shape + (d,)."""
        ts = self._times(t)
        return (self.d0 + self._c * ts) * np.exp(-ts / self.tau)

    def velocity(self, t: ArrayLike) -> FloatArray:
        """D'(t) = (v0 - c t / tau) e^{-t/tau}."""
        ts = self._times(t)
        return (self.v0 - self._c * ts / self.tau) * np.exp(-ts / self.tau)

    def acceleration(self, t: ArrayLike) -> FloatArray:
        """D''(t), from the law itself."""
        return -2.0 / self.tau * self.velocity(t) - self.position(t) / self.tau**2

    def time_to_tolerance(self, eps: float) -> float:
        """First t >= 0 with |D(t)| = eps (0 if |D0| <= eps already).

        |D|^2 = e^{-2t/tau} q(t) with q quadratic, so its critical points are the roots of
        q' - 2q/tau (at most two); between them |D| is monotone, and brentq on the first
        bracket that crosses eps gives the first root.
        """
        _positive(eps, "eps")
        if np.linalg.norm(self.d0) <= eps:
            return 0.0
        c, d0, tau = self._c, self.d0, self.tau
        qa, qb, qc = c @ c, 2.0 * (d0 @ c), d0 @ d0
        roots = np.roots([-2.0 * qa / tau, 2.0 * qa - 2.0 * qb / tau, qb - 2.0 * qc / tau])
        crit = sorted(float(r.real) for r in np.atleast_1d(roots) if abs(r.imag) < 1e-12)
        t_hi = tau
        bound = float(np.linalg.norm(d0))
        speed = float(np.linalg.norm(c))
        while (bound + speed * t_hi) * math.exp(-t_hi / tau) > eps:
            t_hi *= 2.0
        points = [0.0, *[r for r in crit if 0.0 < r < t_hi], t_hi]

        def excess(t: float) -> float:
            return float(np.linalg.norm(self.position(t))) - eps

        for lo, hi in zip(points[:-1], points[1:], strict=True):
            if excess(hi) <= 0.0:
                return float(brentq(excess, lo, hi, xtol=1e-14, rtol=1e-14))
        raise RuntimeError("no crossing found below the decay bound")  # unreachable


@dataclass(frozen=True)
class DynamicConstraintsRollout:
    """A discrete dynamic-constraints trajectory through a goal sequence.

    `times[k]`, `positions[k]`, `velocities[k]` are the state after step k (times[0] = 0 is the
    initial state); `accelerations[k]` is the one applied in step k+1 (last row repeats).
    `met_times[i]` is the time goal i was met (nan if never) and `met_speeds[i]` the speed then.
    """

    times: FloatArray
    positions: FloatArray
    velocities: FloatArray
    accelerations: FloatArray
    met_times: FloatArray
    met_speeds: FloatArray


def simulate(
    start: ArrayLike,
    start_velocity: ArrayLike,
    targets: Sequence[ArrayLike],
    taus: float | Sequence[float],
    eps: float,
    h: float,
    duration: float,
) -> DynamicConstraintsRollout:
    """Drive a point through `targets` with the law, semi-implicit Euler like PyBullet.

    Per step: a = law(D, D'); v += h a; x += h v; then if |x - target| < eps the goal is met
    and the next target becomes current (from the current state). After the last goal the
    point keeps converging on it. `taus` is one value or one per target.
    """
    x = _vector(start, "start").copy()
    v = _vector(start_velocity, "start_velocity").copy()
    if x.shape != v.shape:
        raise ValueError(f"start {x.shape} and start_velocity {v.shape} must match")
    if len(targets) == 0:
        raise ValueError("targets must not be empty")
    nails = [_vector(p, f"targets[{i}]") for i, p in enumerate(targets)]
    if any(n.shape != x.shape for n in nails):
        raise ValueError("every target must have the shape of start")
    tau_list = (
        [float(taus)] * len(nails)
        if isinstance(taus, (int, float, np.number))
        else [float(t) for t in taus]
    )
    if len(tau_list) != len(nails):
        raise ValueError(f"taus has {len(tau_list)} entries for {len(nails)} targets")
    for i, tau in enumerate(tau_list):
        _positive(tau, f"taus[{i}]")
    _positive(eps, "eps")
    _positive(h, "h")
    _positive(duration, "duration")
    n_steps = int(math.ceil(duration / h - 1e-9))
    positions = np.empty((n_steps + 1, x.size))
    velocities = np.empty_like(positions)
    accelerations = np.empty_like(positions)
    positions[0], velocities[0] = x, v
    met_times = np.full(len(nails), math.nan)
    met_speeds = np.full(len(nails), math.nan)
    goal = 0
    while goal < len(nails) and np.linalg.norm(x - nails[goal]) < eps:
        met_times[goal], met_speeds[goal] = 0.0, float(np.linalg.norm(v))
        goal += 1
    for k in range(n_steps):
        current = min(goal, len(nails) - 1)
        a = desired_acceleration(x - nails[current], v, tau_list[current])
        v = v + h * a
        x = x + h * v
        accelerations[k], positions[k + 1], velocities[k + 1] = a, x, v
        while goal < len(nails) and np.linalg.norm(x - nails[goal]) < eps:
            met_times[goal], met_speeds[goal] = (k + 1) * h, float(np.linalg.norm(v))
            goal += 1
    accelerations[n_steps] = accelerations[n_steps - 1] if n_steps else 0.0
    return DynamicConstraintsRollout(
        times=np.arange(n_steps + 1, dtype=float) * h,
        positions=positions,
        velocities=velocities,
        accelerations=accelerations,
        met_times=met_times,
        met_speeds=met_speeds,
    )
