"""The env's reward modes: one :class:`~sgc_env.envs.task.RewardFunction` per mode.

Every mode reads what the observation carries (per body and track: the deviation ``D``, the
time left, the course's start deviation ``D_i(0)`` and duration ``T_i``, the end velocity after
the last goal), the clipped action and the goal-tick events, so a reward is a function of what
the agent observes plus the goal errors of that tick.

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
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from .task import GoalEvent, GoalTask, RewardFunction

__all__ = [
    "EFFORT_WEIGHT",
    "REWARD_MODES",
    "DistanceReward",
    "ScheduleReward",
    "SparseReward",
    "TrackState",
    "distance_cost",
    "goal_bonus",
    "make_reward",
    "schedule_cost",
    "tracks_of",
]

REWARD_MODES: tuple[str, ...] = ("schedule", "distance", "sparse")
EFFORT_WEIGHT = 0.01
POSITION_FLOOR = 0.1  # m
ORIENTATION_FLOOR = 0.5  # rad
TRACK_COST_CAP = 1.0
BONUS_POSITION = 0.01  # m
BONUS_ORIENTATION = 0.02  # rad

TrackState = tuple[Sequence[float], float, Sequence[float]]
"""One track of one body after a step: deviation (D or phi, first 3 entries read), time left
to the current goal, and the course's 13 observation entries (start deviation 3, duration 1,
next start 3, next duration 1, end velocity 3, flags: has a track, is the last goal)."""


def _effort(action: Sequence[float]) -> float:
    return EFFORT_WEIGHT * sum([x * x for x in action]) / len(action)


def goal_bonus(events: Sequence[GoalEvent]) -> float:
    """The bonuses of the goals met this tick (the module docstring; the batched env's too)."""
    total = 0.0
    for ev in events:
        if ev["position_error"] is not None:
            total += math.exp(-ev["position_error"] / BONUS_POSITION)
        if ev["orientation_error"] is not None:
            total += math.exp(-ev["orientation_error"] / BONUS_ORIENTATION)
    return total


def _norm(v: Sequence[float]) -> float:
    return math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])


def schedule_cost(track: TrackState, floor: float) -> float:
    """``min(|D - D_sched| / L, 1)`` (see the module docstring)."""
    d, left, c = track
    if left >= 0.0:
        f = left / c[3]
        rx, ry, rz = c[0] * f, c[1] * f, c[2] * f
    else:
        rx, ry, rz = -c[8] * left, -c[9] * left, -c[10] * left
    error = _norm((d[0] - rx, d[1] - ry, d[2] - rz))
    return min(error / max(_norm(c), floor), TRACK_COST_CAP)


def distance_cost(track: TrackState, floor: float) -> float:
    """``|D| / L`` (uncapped)."""
    d, _, c = track
    return _norm(d) / max(_norm(c), floor)


def tracks_of(task: GoalTask) -> list[tuple[TrackState, float]]:
    """Every track of every body with the floor of its scale (m for position, rad)."""
    out: list[tuple[TrackState, float]] = []
    for i in range(task.n_bodies):
        if task.has_position[i]:
            track: TrackState = (
                task.deviations[i], task.position_time_left[i], task.position_course[i]
            )
            out.append((track, POSITION_FLOOR))
        if task.has_orientation[i]:
            track = (task.phi[i], task.orientation_time_left[i], task.orientation_course[i])
            out.append((track, ORIENTATION_FLOOR))
    return out


class _ModeReward:
    """``-mean_b sum_tracks cost - effort + bonus``, and on a failure the steps left charged at
    the worst per-step reward (where the mode charges failures; its costs must then be capped
    at :data:`TRACK_COST_CAP`)."""

    def __init__(self, cost: Callable[[TrackState, float], float] | None, charge: bool) -> None:
        self._cost = cost
        self._charge = charge

    def __call__(
        self,
        task: GoalTask,
        action: Sequence[float],
        events: Sequence[GoalEvent],
        terminated: bool = False,
        steps_left: int = 0,
    ) -> float:
        cost = worst = 0.0
        if self._cost is not None:
            for track, floor in tracks_of(task):
                cost += self._cost(track, floor)
                worst += TRACK_COST_CAP
        n = task.n_bodies
        reward = -cost / n - _effort(action) + goal_bonus(events)
        if terminated and self._charge:
            reward -= (worst / n + EFFORT_WEIGHT) * steps_left
        return reward


class ScheduleReward(_ModeReward):
    """The default: distance from the on-schedule deviation (capped), effort, bonuses, and the
    failure charge."""

    def __init__(self) -> None:
        super().__init__(schedule_cost, charge=True)


class DistanceReward(_ModeReward):
    """The reward before the modes: ``|D| / L`` per track, effort, bonuses, no failure charge."""

    def __init__(self) -> None:
        super().__init__(distance_cost, charge=False)


class SparseReward(_ModeReward):
    """Goal-tick bonuses and effort only; a failure charges the worst effort per step left."""

    def __init__(self) -> None:
        super().__init__(None, charge=True)


def make_reward(mode: str) -> RewardFunction:
    """The reward function of ``mode`` (one of :data:`REWARD_MODES`)."""
    modes = {"schedule": ScheduleReward, "distance": DistanceReward, "sparse": SparseReward}
    if mode not in modes:
        raise ValueError(f"reward: unknown mode {mode!r}; expected one of {list(REWARD_MODES)}")
    return modes[mode]()
