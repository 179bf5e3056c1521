"""Minimum-jerk paths through timed goals: the smooth baseline a practitioner would pick today.

The path is the clamped quintic spline through the knots (times[j], points[j]) with C4
continuity, velocity and acceleration given at both ends. By the variational property of odd
degree splines (degree 2m - 1 with m = 3) it is the unique minimiser of the integral of
|x'''|^2 among all C2 curves that pass every point at its time with those end conditions:
the Flash & Hogan minimum-jerk path through via points at fixed times. It is built with
scipy.interpolate.make_interp_spline(k=5). With two knots from rest to rest it is the classic
x0 + (x1 - x0)(10 s^3 - 15 s^4 + 6 s^5).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.interpolate import make_interp_spline
from scipy.spatial.transform import Rotation

from sgc_env.paper import quaternion as quat
from sgc_env.paper.orientation import left_jacobian

FloatArray = NDArray[np.float64]


def _finite(value: ArrayLike, name: str) -> FloatArray:
    arr = np.asarray(value, dtype=float)
    if arr.size == 0:
        raise ValueError(f"{name} must not be empty")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be finite (no NaN or inf)")
    return arr


def _vector_like(value: ArrayLike | None, dim: int, name: str) -> FloatArray:
    if value is None:
        return np.zeros(dim)
    arr = _finite(value, name).reshape(-1)
    if arr.size != dim:
        raise ValueError(f"{name} must have {dim} entries, got {arr.size}")
    return arr


class MinimumJerkPath:
    """C4 quintic spline x(t) through `points` at `times` (first row: the initial state).

    `times` (n+1,) strictly increasing; `points` (n+1, d) or (n+1,); `v0`, `a0` the initial
    velocity and acceleration (a0 None: zero); `end_velocity` the velocity at the last goal
    (None: the last course's average velocity); `end_acceleration` (default zero).
    Evaluation outside [times[0], times[-1]] extrapolates the end polynomials.
    """

    def __init__(
        self,
        times: ArrayLike,
        points: ArrayLike,
        v0: ArrayLike,
        a0: ArrayLike | None = None,
        end_velocity: ArrayLike | None = None,
        end_acceleration: ArrayLike | None = None,
    ) -> None:
        t = _finite(times, "times")
        if t.ndim != 1:
            raise ValueError(f"times must be 1-D, got shape {t.shape}")
        if t.size < 2:
            raise ValueError("times must hold the start and at least one goal")
        if np.any(np.diff(t) <= 0.0):
            raise ValueError("times must be strictly increasing")
        p = _finite(points, "points")
        self._scalar = p.ndim == 1
        p = p.reshape(p.shape[0], -1) if p.ndim >= 1 else p
        if p.ndim != 2 or p.shape[0] != t.size:
            raise ValueError(f"points must have {t.size} rows (one per time), got {p.shape}")
        dim = p.shape[1]
        start_v = _vector_like(v0, dim, "v0")
        start_a = _vector_like(a0, dim, "a0")
        if end_velocity is None:
            end_v = (p[-1] - p[-2]) / (t[-1] - t[-2])
        else:
            end_v = _vector_like(end_velocity, dim, "end_velocity")
        end_a = _vector_like(end_acceleration, dim, "end_acceleration")
        self.times = t
        self.points = p
        self._spline = make_interp_spline(
            t, p, k=5, bc_type=([(1, start_v), (2, start_a)], [(1, end_v), (2, end_a)])
        )

    def _eval(self, t: ArrayLike, nu: int) -> FloatArray:
        ts = np.asarray(t, dtype=float)
        if not np.all(np.isfinite(ts)):
            raise ValueError("t must be finite")
        out = self._spline(ts, nu=nu)
        return out[..., 0] if self._scalar else out

    def position(self, t: ArrayLike) -> FloatArray:
        """x(t), shape t.shape + (d,) (t.shape for scalar points)."""
        return self._eval(t, 0)

    def velocity(self, t: ArrayLike) -> FloatArray:
        """x'(t)."""
        return self._eval(t, 1)

    def acceleration(self, t: ArrayLike) -> FloatArray:
        """x''(t)."""
        return self._eval(t, 2)

    def jerk(self, t: ArrayLike) -> FloatArray:
        """x'''(t)."""
        return self._eval(t, 3)


class MinimumJerkRotation:
    """Minimum-jerk orientation path: the same spline on a rotation vector phi(t).

    R(t) = Exp(phi(t)) R0 with phi(times[0]) = 0; each goal orientation becomes a knot phi_j
    with Exp(phi_j) = R_j R0^-1, unwrapped to the representative nearest phi_{j-1} + r_j where
    r_j is the optional per-course rotation vector (`rotations`, world frame; a somersault is
    one longer than pi), else nearest phi_{j-1}. The spline is minimum-jerk in phi, not in
    the rotation itself; the difference is second order in the angle and vanishes for
    rotations about a fixed axis. Angular rates map through the left Jacobian.
    """

    def __init__(
        self,
        times: ArrayLike,
        orientations: ArrayLike,
        omega0: ArrayLike,
        rotations: Sequence[ArrayLike] | None = None,
        end_omega: ArrayLike | None = None,
    ) -> None:
        quats = _finite(orientations, "orientations")
        if quats.ndim != 2 or quats.shape[1] != 4:
            raise ValueError(f"orientations must have shape (n+1, 4), got {quats.shape}")
        if np.any(np.linalg.norm(quats, axis=1) < 1e-9):
            raise ValueError("orientations must be nonzero quaternions")
        if rotations is not None and len(rotations) != quats.shape[0] - 1:
            raise ValueError(
                f"rotations must have {quats.shape[0] - 1} entries (one per course), "
                f"got {len(rotations)}"
            )
        self.start = Rotation.from_quat(quats[0])
        knots: list[Any] = [np.zeros(3)]
        for j in range(1, quats.shape[0]):
            rel = (Rotation.from_quat(quats[j]) * self.start.inv()).as_rotvec()
            guess = knots[-1]
            if rotations is not None:
                guess = guess + _vector_like(rotations[j - 1], 3, f"rotations[{j - 1}]")
            knots.append(np.array(quat.unwrap_rotvec(rel, guess)))
        phi = np.array(knots)
        w0 = _vector_like(omega0, 3, "omega0")
        phi_end_rate = None
        if end_omega is not None:
            w_end = _vector_like(end_omega, 3, "end_omega")
            phi_end_rate = np.linalg.solve(left_jacobian(phi[-1]), w_end)
        self.phi_path = MinimumJerkPath(times, phi, w0, end_velocity=phi_end_rate)

    def rotation_vector(self, t: ArrayLike) -> FloatArray:
        """phi(t), unwrapped (may be longer than pi)."""
        return self.phi_path.position(t)

    def orientation(self, t: ArrayLike) -> FloatArray:
        """Quaternions xyzw of R(t) = Exp(phi(t)) R0, shape t.shape + (4,)."""
        phi = self.rotation_vector(t)
        flat = phi.reshape(-1, 3)
        quats = (Rotation.from_rotvec(flat) * self.start).as_quat()
        return quats.reshape(*phi.shape[:-1], 4)

    def angular_velocity(self, t: ArrayLike) -> FloatArray:
        """World angular velocity omega = J(phi) phi', shape t.shape + (3,)."""
        phi = self.rotation_vector(t).reshape(-1, 3)
        rate = self.phi_path.velocity(t).reshape(-1, 3)
        omega = np.array([left_jacobian(p) @ r for p, r in zip(phi, rate, strict=True)])
        return omega.reshape(self.rotation_vector(t).shape)
