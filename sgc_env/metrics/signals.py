"""Pure metric functions on numpy arrays.

Everything here takes sampled signals (times, values) and returns numbers; nothing knows about
environments or goals. The scoring layer (`sgc_env.metrics.scoring`) combines them.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.signal import find_peaks

FloatArray = NDArray[np.float64]

#: Times closer than this (s) count as equal: goal times and ticks like (k + 1) * dt differ by
#: float round-off, and a goal on a tick must use that tick's sample.
TIME_SLACK = 1e-9


def as_finite_array(values: ArrayLike, name: str, ndim: int | None = None) -> FloatArray:
    """Convert to a float array and reject empty input or NaN/inf, naming the argument."""
    arr = np.asarray(values, dtype=float)
    if ndim is not None and arr.ndim != ndim:
        raise ValueError(f"{name} must have {ndim} dimension(s), got shape {arr.shape}")
    if arr.size == 0:
        raise ValueError(f"{name} must not be empty")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be finite (no NaN or inf)")
    return arr


def check_times(times: ArrayLike, name: str = "times") -> FloatArray:
    """Return `times` as a 1-D float array, requiring it to be strictly increasing."""
    t = as_finite_array(times, name, ndim=1)
    if np.any(np.diff(t) <= 0.0):
        raise ValueError(f"{name} must be strictly increasing")
    return t


def _check_same_length(times: FloatArray, values: FloatArray, name: str) -> None:
    if values.shape[0] != times.shape[0]:
        raise ValueError(f"{name} has {values.shape[0]} samples but times has {times.shape[0]}")


def _check_positive(value: float, name: str) -> float:
    if not math.isfinite(value) or value <= 0.0:
        raise ValueError(f"{name} must be a finite positive number, got {value}")
    return float(value)


def locate(times: FloatArray, t: float) -> tuple[int, bool]:
    """Index k of the last tick at or before `t` (within TIME_SLACK) and whether t is on it.

    k is -1 when t precedes every tick.
    """
    k = int(np.searchsorted(times, t + TIME_SLACK, side="right")) - 1
    return k, k >= 0 and abs(times[k] - t) <= TIME_SLACK


def in_window(times: FloatArray, t_start: float, t_end: float) -> NDArray[np.intp]:
    """Indices of the ticks inside [t_start, t_end], widened by TIME_SLACK."""
    return np.flatnonzero((times >= t_start - TIME_SLACK) & (times <= t_end + TIME_SLACK))


def interpolate_at(times: ArrayLike, values: ArrayLike, t: float) -> FloatArray:
    """Linear interpolation of samples at time `t`; returns the sample itself on a tick.

    Linear is the honest model between control ticks: PyBullet's semi-implicit Euler moves a
    free body along a straight line within a step. Times outside the samples are clamped.
    """
    ts = check_times(times)
    vals = as_finite_array(values, "values")
    _check_same_length(ts, vals, "values")
    if not math.isfinite(t):
        raise ValueError(f"t must be finite, got {t}")
    k, on_tick = locate(ts, t)
    if on_tick:
        return np.array(vals[k], dtype=float)
    if k < 0:
        return np.array(vals[0], dtype=float)
    if k == ts.size - 1:
        return np.array(vals[-1], dtype=float)
    w = (t - ts[k]) / (ts[k + 1] - ts[k])
    return (1.0 - w) * vals[k] + w * vals[k + 1]


def closest_approach(
    times: ArrayLike, distance: ArrayLike, t_start: float, t_end: float
) -> tuple[float, float]:
    """Time and value of the closest approach within [t_start, t_end], refined sub-tick.

    ``distance`` is either the offsets from the target, shape (n, k), or scalar distances,
    shape (n,). Offsets are refined on the straight segments between samples (the linear
    interpolation that :func:`interpolate_at` also uses): exact at an exact hit on a tick
    whatever the speeds before and after it, and exact for straight-line motion between
    ticks. Scalar distances fall back to a parabola through the squared distance at the best
    sample and its two neighbours, kept only if its vertex lies between them and inside the
    window; that one is biased by up to half a tick when the speed changes at the goal.
    Returns (nan, nan) if no sample lies in the window.
    """
    ts = check_times(times)
    values = np.asarray(distance, dtype=float)
    if values.ndim == 2:
        offsets = as_finite_array(values, "distance", ndim=2)
        _check_same_length(ts, offsets, "distance")
        return _closest_on_segments(ts, offsets, t_start, t_end)
    d = as_finite_array(values, "distance", ndim=1)
    _check_same_length(ts, d, "distance")
    if not t_end >= t_start:
        raise ValueError(f"t_end ({t_end}) must not precede t_start ({t_start})")
    inside = in_window(ts, t_start, t_end)
    if inside.size == 0:
        return math.nan, math.nan
    k = int(inside[np.argmin(d[inside])])
    best_t, best_d = float(ts[k]), float(d[k])
    if k == 0 or k == ts.size - 1:
        return best_t, best_d
    t3 = ts[k - 1 : k + 2]
    y3 = d[k - 1 : k + 2] ** 2
    coeffs = np.polyfit(t3 - ts[k], y3, 2)
    if coeffs[0] <= 0.0:
        return best_t, best_d
    vertex = -coeffs[1] / (2.0 * coeffs[0]) + ts[k]
    if not (t3[0] <= vertex <= t3[2] and t_start - TIME_SLACK <= vertex <= t_end + TIME_SLACK):
        return best_t, best_d
    value = float(np.polyval(coeffs, vertex - ts[k]))
    return float(vertex), math.sqrt(max(value, 0.0))


def _closest_on_segments(
    ts: FloatArray, offsets: FloatArray, t_start: float, t_end: float
) -> tuple[float, float]:
    """Closest approach of the polyline through ``offsets`` to the origin, inside the window."""
    if not t_end >= t_start:
        raise ValueError(f"t_end ({t_end}) must not precede t_start ({t_start})")
    inside = in_window(ts, t_start, t_end)
    if inside.size == 0:
        return math.nan, math.nan
    lo, hi = int(inside[0]), int(inside[-1])
    a, b = offsets[lo:hi], offsets[lo + 1 : hi + 1]
    if a.shape[0] == 0:
        return float(ts[lo]), float(np.linalg.norm(offsets[lo]))
    step = b - a
    length2 = np.einsum("ij,ij->i", step, step)
    with np.errstate(invalid="ignore", divide="ignore"):
        s = np.where(length2 > 0.0, -np.einsum("ij,ij->i", a, step) / length2, 0.0)
    s = np.clip(s, 0.0, 1.0)
    nearest = a + s[:, None] * step
    d = np.linalg.norm(nearest, axis=1)
    k = int(np.argmin(d))
    return float(ts[lo + k] + s[k] * (ts[lo + k + 1] - ts[lo + k])), float(d[k])


def first_entry(
    times: ArrayLike, distance: ArrayLike, tolerance: float, t_start: float, t_end: float
) -> float:
    """First time in [t_start, t_end] at which `distance` falls to `tolerance` or below.

    The crossing is interpolated linearly between the ticks around it. If the signal is
    already inside at the first sample of the window, that sample's time is returned; if it
    never enters, nan.
    """
    ts = check_times(times)
    d = as_finite_array(distance, "distance", ndim=1)
    _check_same_length(ts, d, "distance")
    _check_positive(tolerance, "tolerance")
    inside = in_window(ts, t_start, t_end)
    if inside.size == 0:
        return math.nan
    hits = inside[d[inside] <= tolerance]
    if hits.size == 0:
        return math.nan
    k = int(hits[0])
    if k == inside[0] or k == 0:
        return float(ts[k])
    d0, d1 = d[k - 1], d[k]
    w = (d0 - tolerance) / (d0 - d1)
    return float(max(ts[k - 1] + w * (ts[k] - ts[k - 1]), t_start))


def sparc(
    speed: ArrayLike,
    fs: float,
    padlevel: int = 4,
    fc: float = 10.0,
    amp_th: float = 0.05,
) -> float:
    """Spectral arc length (Balasubramanian et al. 2012, 2015) of a speed profile.

    Same definition as the authors' reference code: zero-pad to the next power of two times
    2**padlevel, normalise the magnitude spectrum by its peak, keep frequencies up to `fc`
    and then the band between the first and last bins at or above `amp_th`, and return minus
    the arc length of the normalised spectrum over frequency normalised by that band's width.
    Unlike the reference code only the one-sided spectrum is used and `fc` is capped at the
    Nyquist frequency, so a low sampling rate never adds mirrored bins. Returns nan for a
    signal that is zero everywhere (no movement, no spectrum to normalise).
    """
    v = as_finite_array(speed, "speed", ndim=1)
    _check_positive(fs, "fs")
    _check_positive(fc, "fc")
    if padlevel < 0:
        raise ValueError(f"padlevel must be >= 0, got {padlevel}")
    if not 0.0 < amp_th < 1.0:
        raise ValueError(f"amp_th must lie in (0, 1), got {amp_th}")
    if v.size < 2:
        raise ValueError("speed must have at least 2 samples")
    nfft = int(2 ** (math.ceil(math.log2(v.size)) + padlevel))
    freqs = np.fft.rfftfreq(nfft, d=1.0 / fs)
    mag = np.abs(np.fft.rfft(v, nfft))
    peak = mag.max()
    if peak == 0.0:
        return math.nan
    mag = mag / peak
    keep = freqs <= min(fc, fs / 2.0)
    f_sel, m_sel = freqs[keep], mag[keep]
    above = np.flatnonzero(m_sel >= amp_th)
    f_sel = f_sel[above[0] : above[-1] + 1]
    m_sel = m_sel[above[0] : above[-1] + 1]
    if f_sel.size < 2:
        return 0.0
    df = np.diff(f_sel) / (f_sel[-1] - f_sel[0])
    return -float(np.sum(np.sqrt(df**2 + np.diff(m_sel) ** 2)))


def ldlj(velocity: ArrayLike, dt: float) -> float:
    """Log dimensionless jerk of a velocity profile (Balasubramanian et al. 2015, LDLJ-V).

    -ln( (t2 - t1)^3 / v_peak^2 * integral |d^2 v / dt^2|^2 dt ), with v the velocity vector
    (a 1-D array is a scalar velocity), v_peak its largest norm, t2 - t1 = n * dt as in the
    reference code, and the second derivative from second differences. Needs at least 3
    samples; returns nan for a signal that never moves. Very sensitive to noise: the second
    difference amplifies white noise by 1/dt^2.
    """
    v = as_finite_array(velocity, "velocity")
    _check_positive(dt, "dt")
    if v.ndim == 1:
        v = v[:, None]
    if v.ndim != 2:
        raise ValueError(f"velocity must be 1-D or 2-D, got shape {v.shape}")
    if v.shape[0] < 3:
        raise ValueError("velocity must have at least 3 samples")
    v_peak = float(np.max(np.linalg.norm(v, axis=1)))
    if v_peak == 0.0:
        return math.nan
    duration = v.shape[0] * dt
    jerk = np.diff(v, 2, axis=0) / dt**2
    integral = float(np.sum(jerk**2)) * dt
    if integral == 0.0:
        return math.inf
    return -math.log(duration**3 / v_peak**2 * integral)


def speed_minima(speed: ArrayLike, min_prominence: float) -> FloatArray:
    """Indices of local minima of `speed` whose prominence is at least `min_prominence`.

    Minima at the first or last sample are not counted (a movement starting or ending at rest
    is not a superfluous stop).
    """
    v = as_finite_array(speed, "speed", ndim=1)
    if not min_prominence >= 0.0:
        raise ValueError(f"min_prominence must be >= 0, got {min_prominence}")
    idx, _ = find_peaks(-v, prominence=min_prominence)
    return idx


def velocity_jump(times: ArrayLike, velocity: ArrayLike, t: float) -> float:
    """Largest one-tick change of velocity at an event at time `t`: into it and out of it.

    Sample k holds the velocity over the step (t_{k-1}, t_k] (semi-implicit Euler), so for an
    event on or after tick k and before tick k+1 the step out of it changes the velocity by
    |v_{k+1} - v_k| and the step into it by |v_k - v_{k-1}|; the larger is returned. A
    controller can hide a kink in the last tick before a goal (a ramp) as well as in the first
    one after it, so both count. Returns nan if there is no sample after the event.
    """
    ts = check_times(times)
    v = as_finite_array(velocity, "velocity")
    _check_same_length(ts, v, "velocity")
    k, _ = locate(ts, t)
    if k < 0 or k + 1 >= ts.size:
        return math.nan
    jump = float(np.linalg.norm(np.atleast_1d(v[k + 1] - v[k])))
    if k >= 1:
        jump = max(jump, float(np.linalg.norm(np.atleast_1d(v[k] - v[k - 1]))))
    return jump


def accelerations(velocity: ArrayLike, dt: float) -> FloatArray:
    """Per-step accelerations (v_k - v_{k-1}) / dt, shape (n - 1, ...) for n velocity samples.

    With semi-implicit Euler this is exactly the acceleration applied in step k.
    """
    v = as_finite_array(velocity, "velocity")
    _check_positive(dt, "dt")
    if v.shape[0] < 2:
        raise ValueError("velocity must have at least 2 samples")
    return np.diff(v, axis=0) / dt


def acceleration_peak_and_kink(velocity: ArrayLike, dt: float) -> tuple[float, float]:
    """Peak |a| and the largest one-tick change of acceleration |a_{k+1} - a_k| (the "kink").

    Over every tick of the signal, so a jump of acceleration at a goal or at a boundary that
    no goal marks (a split somersault's sub-course) is seen wherever it is. Units: those of
    the velocity per second (the kink is the change within one tick, not divided by dt, so it
    compares methods at the same dt). nan where there are too few samples.
    """
    v = as_finite_array(velocity, "velocity")
    if v.ndim == 1:
        v = v[:, None]
    if v.shape[0] < 2:
        return math.nan, math.nan
    a = accelerations(v, dt)
    peak = float(np.max(np.linalg.norm(a, axis=1)))
    if a.shape[0] < 2:
        return peak, math.nan
    return peak, float(np.max(np.linalg.norm(np.diff(a, axis=0), axis=1)))


def step_weights(times: ArrayLike, dt: float, t_start: float, t_end: float) -> FloatArray:
    """Seconds of each step (t_k - dt, t_k] that fall inside [t_start, t_end].

    Used to integrate per-step quantities (held forces, semi-implicit velocities) over a time
    interval that need not start or end on a tick.
    """
    ts = check_times(times)
    _check_positive(dt, "dt")
    lo = np.maximum(ts - dt, t_start)
    hi = np.minimum(ts, t_end)
    return np.clip(hi - lo, 0.0, None)


def integral_of_squares(values: ArrayLike, weights: ArrayLike) -> float:
    """Sum of |x_k|^2 w_k: the integral of a piecewise-constant squared norm (N^2 s, ...)."""
    x = as_finite_array(values, "values")
    w = as_finite_array(weights, "weights", ndim=1)
    if x.shape[0] != w.shape[0]:
        raise ValueError(f"values has {x.shape[0]} samples but weights has {w.shape[0]}")
    sq = x**2 if x.ndim == 1 else np.sum(x**2, axis=1)
    return float(np.sum(sq * w))


def angle_travelled(angular_velocity: ArrayLike, weights: ArrayLike) -> float:
    """Integral of |omega| dt for piecewise-constant angular velocity (rad)."""
    w_vec = as_finite_array(angular_velocity, "angular_velocity", ndim=2)
    wts = as_finite_array(weights, "weights", ndim=1)
    if w_vec.shape[0] != wts.shape[0]:
        raise ValueError(
            f"angular_velocity has {w_vec.shape[0]} samples but weights has {wts.shape[0]}"
        )
    return float(np.sum(np.linalg.norm(w_vec, axis=1) * wts))


def rotation_ratio(travelled: float, needed: float, angle_floor: float) -> float:
    """Angle travelled over angle needed, with the needed angle floored at `angle_floor`.

    The floor makes the ratio defined for a course that needs no rotation: turning by less
    than the floor (by default the orientation tolerance) scores at most 1.
    """
    _check_positive(angle_floor, "angle_floor")
    if not (travelled >= 0.0 and needed >= 0.0):
        raise ValueError(f"travelled and needed must be >= 0, got {travelled}, {needed}")
    return travelled / max(needed, angle_floor)


def safe_mean(values: ArrayLike) -> float:
    """Mean over finite entries; nan if there are none (no RuntimeWarning)."""
    arr = np.asarray(values, dtype=float).ravel()
    arr = arr[np.isfinite(arr)]
    return float(arr.mean()) if arr.size else math.nan


def safe_max(values: ArrayLike) -> float:
    """Max over non-nan entries; nan if there are none."""
    arr = np.asarray(values, dtype=float).ravel()
    arr = arr[~np.isnan(arr)]
    return float(arr.max()) if arr.size else math.nan
