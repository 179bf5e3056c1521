"""Routing-time allocation (Liu, Ko & Chang 1993, section 3).

Between two consecutive time-critical goals at ``t_a`` and ``t_b`` the times of the goals in
between are not given: they are allocated so that the average speed of course ``i``,
``|D_i(0)| / T_i``, is proportional to its routing weight ``w_i``. Hence ``T_i`` is proportional
to ``|D_i(0)| / w_i`` and the durations of the segment add up to ``t_b - t_a``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

__all__ = ["allocate_course_durations", "cumulative_fractions", "resolve_goal_times"]


def _finite_positive(values: np.ndarray, name: str, *, allow_zero: bool) -> None:
    for i, v in enumerate(values):
        if not np.isfinite(v):
            raise ValueError(f"{name}[{i}] must be finite, got {v!r}")
        if v < 0 or (v == 0 and not allow_zero):
            bound = ">= 0" if allow_zero else "> 0"
            raise ValueError(f"{name}[{i}] must be {bound}, got {v!r}")


def cumulative_fractions(share: np.ndarray) -> np.ndarray:
    """Fractions of the segment elapsed at each goal; the last is exactly 1."""
    cumulative = np.cumsum(share) / share.sum()
    cumulative[-1] = 1.0
    return cumulative


def allocate_course_durations(
    distances: Sequence[float], weights: Sequence[float], total_time: float
) -> np.ndarray:
    """Split ``total_time`` over courses so that average speeds are in the ratio of weights.

    ``distances[i]`` is ``|D_i(0)|`` and ``weights[i]`` is ``w_i``. Each duration is computed
    directly as ``total * share_i / sum(share)`` (ratios exact to rounding even for a tiny
    course next to a long one); the largest is then corrected so that the exactly rounded sum
    ``math.fsum(durations)`` equals ``total_time``.
    """
    d = np.asarray(distances, dtype=float)
    w = np.asarray(weights, dtype=float)
    if d.ndim != 1 or d.size == 0:
        raise ValueError("distances must be a non-empty 1-D sequence")
    if w.shape != d.shape:
        raise ValueError(f"weights has shape {w.shape}, distances has shape {d.shape}")
    _finite_positive(d, "distances", allow_zero=False)
    _finite_positive(w, "weights", allow_zero=False)
    if not (np.isfinite(total_time) and total_time > 0):
        raise ValueError(f"total_time must be finite and > 0, got {total_time!r}")
    share = d / w
    durations = total_time * (share / share.sum())
    order = np.argsort(-durations)
    durations[order[0]] += total_time - math.fsum(durations)
    # The last ulps: step the largest durations one ulp at a time towards the exact total (a
    # tie in the rounding of the sum can need a second element).
    for i in order[:3]:
        for _ in range(4):
            total = math.fsum(durations)
            if total == total_time:
                return durations
            durations[i] = np.nextafter(durations[i], np.inf if total < total_time else -np.inf)
    return durations


def resolve_goal_times(
    times: Sequence[float | None],
    critical: Sequence[bool],
    distances: Sequence[float],
    weights: Sequence[float],
    start_time: float = 0.0,
) -> np.ndarray:
    """Fill in the times of non-critical goals from routing weights.

    ``distances[i]`` is the length of course ``i`` (from goal ``i-1``, or the initial state,
    to goal ``i``). Time-critical goals keep their time; the last goal must be time-critical so
    that every non-critical goal lies between two anchors (the start counts as one).
    Raises ValueError naming the offending goal.
    """
    n = len(times)
    if n == 0:
        raise ValueError("the goal list is empty")
    if not (len(critical) == len(distances) == len(weights) == n):
        raise ValueError("times, critical, distances and weights must have the same length")
    resolved = np.full(n, np.nan)
    anchor_index, anchor_time = -1, float(start_time)
    for i in range(n):
        t = times[i]
        if critical[i]:
            if t is None or not np.isfinite(t):
                raise ValueError(f"goal {i}: a time-critical goal needs a finite time, got {t!r}")
            if t <= anchor_time:
                raise ValueError(
                    f"goal {i}: time {t} is not after the previous time-critical time "
                    f"{anchor_time}; goal times must increase"
                )
            segment = range(anchor_index + 1, i + 1)
            seg_d = [distances[j] for j in segment]
            seg_w = [weights[j] for j in segment]
            for j, (dj, wj) in zip(segment, zip(seg_d, seg_w, strict=True), strict=True):
                if not (np.isfinite(wj) and wj > 0):
                    raise ValueError(f"goal {j}: routing weight must be finite and > 0, got {wj!r}")
                if len(segment) > 1 and not (np.isfinite(dj) and dj > 0):
                    raise ValueError(
                        f"goal {j}: course length is {dj!r}; a non-critical goal needs a "
                        "positive distance from the previous goal (make a dwell time-critical)"
                    )
            if len(segment) == 1:
                resolved[i] = t
            else:
                share = np.asarray(seg_d, dtype=float) / np.asarray(seg_w, dtype=float)
                elapsed = (t - anchor_time) * cumulative_fractions(share)
                resolved[list(segment)] = anchor_time + elapsed
                resolved[i] = t
            anchor_index, anchor_time = i, float(t)
        elif t is not None:
            raise ValueError(
                f"goal {i}: has time {t} but is not time-critical; non-critical goals get their "
                "time from routing weights (drop the time or mark the goal critical)"
            )
    if anchor_index != n - 1:
        raise ValueError(f"goal {n - 1}: the last goal must be time-critical (it has no time)")
    return resolved
