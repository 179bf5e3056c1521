"""The env's reward modes: one small object per mode, computed from one step's record.

Every mode reads the same things the observation carries (per body and track: the deviation
``D``, the time left, the course's start deviation ``D_i(0)`` and duration ``T_i``, the end
velocity after the last goal, the flags), the clipped action and the goal-tick events, so a
reward is a function of what the agent observes plus the goal errors of that tick.

``schedule`` (the default), per step::

    r = - mean_b sum_tracks min(|D - D_sched| / L, 1) - 0.01 mean(a^2) + bonuses
    D_sched = D_i(0) * time_left / T_i            before and on the goal's tick
    D_sched = - v_end * time_left                 after the last goal (time_left < 0)
    bonuses = sum over goals met this tick of exp(-|D| / 0.01 m) (+ exp(-|phi| / 0.02 rad))

with ``L = max(|D_i(0)|, 0.1 m)`` and, for orientation, ``phi`` in place of ``D`` and
``L = max(|phi_i(0)|, 0.5 rad)``. Why this reference: ``D_sched`` is the paper's behaviour
equation ``D'' - 2a D' + (a^2 + b^2) D = 0`` with end conditions ``D(T) = 0, D'(T) = -k D0/T``
in its neutral member (``k = 1``, ``a = b = 0``): the course travelled at its average speed, on
schedule. It depends only on the course (``D_i(0)``, ``T_i``) and the clock, never on the
agent's own state, so the cost is zero only for a body that is where the course says it should
be *now*; arriving early and hovering on the nail costs ``time_left / T_i`` per step, arriving
late costs the same, and the tick's bonus pays only for exactness on the tick. After the last
goal the body should carry on at the goal's end velocity. The SGC expert deviates from the
neutral course only by its smooth start (it enters each course with the previous course's end
velocity), so it earns near the maximum.

``distance`` (the env's reward before ``schedule``): ``r = - mean_b (|D| / L + |phi| / A) -
0.01 mean(a^2) + bonuses``. It pays for reaching the nail early and hovering there, and a
failure ends the negative stream, so it ranks the early, inexact dynamic-constraints controller
above the expert; kept for comparison with earlier results.

``sparse``: ``r = - 0.01 mean(a^2) + bonuses``.

Failure: ``schedule`` and ``sparse`` charge the steps a failed (terminated) episode leaves,
each at the mode's worst per-step reward (``schedule``: ``mean_b(number of tracks) + 0.01``;
``sparse``: ``0.01``), so that leaving the workspace is never better than staying; with the
per-track cost capped at 1 no state is worse than that. ``distance`` keeps its old behaviour
(no charge).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from sgc_env.observation import ObservationLayout

__all__ = ["REWARD_MODES", "EFFORT_WEIGHT", "make_reward"]

REWARD_MODES: tuple[str, ...] = ("schedule", "distance", "sparse")
EFFORT_WEIGHT = 0.01
POSITION_FLOOR = 0.1  # m
ORIENTATION_FLOOR = 0.5  # rad
TRACK_COST_CAP = 1.0
BONUS_POSITION = 0.01  # m
BONUS_ORIENTATION = 0.02  # rad

_TRACK_FIELDS = ("deviation", "time_left", "course_start", "course_duration", "end_velocity",
                 "flags")  # fmt: skip


def _columns() -> list[int]:
    """Block offsets of each track's fields, in the order :func:`_track_terms` reads them."""
    layout = ObservationLayout(1)
    cols: list[int] = []
    for track in ("position", "orientation"):
        for name in _TRACK_FIELDS:
            sl = layout.body_slice(0, f"{track}_{name}")
            cols += range(sl.start, sl.stop)
    return cols


_COLUMNS = _columns()
_PER_TRACK = 13  # 3 + 1 + 3 + 1 + 3 + 2


def _effort(action: Sequence[float]) -> float:
    return EFFORT_WEIGHT * sum([x * x for x in action]) / len(action)


def _bonus(events: Sequence[dict[str, Any]]) -> float:
    total = 0.0
    for ev in events:
        if ev["position_error"] is not None:
            total += math.exp(-ev["position_error"] / BONUS_POSITION)
        if ev["orientation_error"] is not None:
            total += math.exp(-ev["orientation_error"] / BONUS_ORIENTATION)
    return total


def _track_rows(block: np.ndarray) -> list[list[float]]:
    """Per body: the 26 track entries (position then orientation) as plain floats."""
    return block[:, _COLUMNS].tolist()


def _schedule_cost(v: list[float], o: int, floor: float) -> float:
    """``min(|D - D_sched| / L, 1)`` of the track starting at ``v[o]`` (0 without a track)."""
    if v[o + 11] < 0.5:
        return 0.0
    dx, dy, dz, left = v[o], v[o + 1], v[o + 2], v[o + 3]
    sx, sy, sz = v[o + 4], v[o + 5], v[o + 6]
    if left >= 0.0:
        f = left / v[o + 7]
        rx, ry, rz = sx * f, sy * f, sz * f
    else:
        rx, ry, rz = -v[o + 8] * left, -v[o + 9] * left, -v[o + 10] * left
    ex, ey, ez = dx - rx, dy - ry, dz - rz
    scale = max(math.sqrt(sx * sx + sy * sy + sz * sz), floor)
    return min(math.sqrt(ex * ex + ey * ey + ez * ez) / scale, TRACK_COST_CAP)


def _distance_cost(v: list[float], o: int, floor: float) -> float:
    if v[o + 11] < 0.5:
        return 0.0
    dx, dy, dz = v[o], v[o + 1], v[o + 2]
    sx, sy, sz = v[o + 4], v[o + 5], v[o + 6]
    scale = max(math.sqrt(sx * sx + sy * sy + sz * sz), floor)
    return math.sqrt(dx * dx + dy * dy + dz * dz) / scale


class TrackReward:
    """Dense modes: a per-track cost averaged over bodies, effort, bonuses, failure charge."""

    def __init__(self, cost, charge_failure: bool) -> None:
        self._cost = cost
        self._charge_failure = charge_failure

    def __call__(
        self,
        block: np.ndarray,
        action: Sequence[float],
        events: Sequence[dict[str, Any]],
        terminated: bool,
        steps_left: int,
    ) -> float:
        """Reward of one step; ``block`` is the (bodies, block) double record of the step."""
        rows = _track_rows(block)
        cost = sum(
            self._cost(v, 0, POSITION_FLOOR) + self._cost(v, _PER_TRACK, ORIENTATION_FLOOR)
            for v in rows
        ) / len(rows)
        reward = -cost - _effort(action) + _bonus(events)
        if terminated and self._charge_failure:
            tracks = sum((v[11] > 0.5) + (v[_PER_TRACK + 11] > 0.5) for v in rows) / len(rows)
            reward -= (TRACK_COST_CAP * tracks + EFFORT_WEIGHT) * steps_left
        return reward


class SparseReward:
    """Goal-tick bonuses and effort only; a failure charges the worst effort per step left."""

    def __call__(
        self,
        block: np.ndarray,
        action: Sequence[float],
        events: Sequence[dict[str, Any]],
        terminated: bool,
        steps_left: int,
    ) -> float:
        reward = -_effort(action) + _bonus(events)
        if terminated:
            reward -= EFFORT_WEIGHT * steps_left
        return reward


def make_reward(mode: str) -> TrackReward | SparseReward:
    """The reward object of ``mode`` (one of :data:`REWARD_MODES`)."""
    if mode == "schedule":
        return TrackReward(_schedule_cost, charge_failure=True)
    if mode == "distance":
        return TrackReward(_distance_cost, charge_failure=False)
    if mode == "sparse":
        return SparseReward()
    raise ValueError(f"reward: unknown mode {mode!r}; expected one of {list(REWARD_MODES)}")
