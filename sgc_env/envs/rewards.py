"""The env's reward modes: one :class:`RewardMode` class per mode, each with one method.

A mode's :meth:`RewardMode.reward` scores a :class:`StepScore`, the same for one env (floats)
and for the batched env (arrays over sub-envs): its arithmetic is elementwise and its branches
go through :mod:`sgc_env.paper.elementwise`, so both envs run this code and agree bit for bit.
``gym.make(id, reward=...)`` and ``gym.make_vec(id, n, reward=...)`` take a mode's name
(:data:`REWARD_MODES`) or a :class:`RewardMode` instance, a mode of the caller's own. Adding a
mode is one subclass here, registered by :func:`reward_mode`.

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
import sys
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from sgc_env.paper.elementwise import all_, any_, at_least, at_most, sqrt, where

from .choices import choose

if TYPE_CHECKING:
    from .task import GoalEvent, GoalTask

__all__ = [
    "EFFORT_WEIGHT",
    "REWARD_MODES",
    "DistanceReward",
    "RewardMode",
    "ScheduleReward",
    "SparseReward",
    "StepScore",
    "TrackingReward",
    "TrackReading",
    "distance_cost",
    "effort",
    "failure_charge",
    "goal_bonus",
    "make_reward",
    "reward_mode",
    "schedule_cost",
    "schedule_error",
    "square_sum",
    "track_costs",
    "tracking_score",
    "tracks_of",
]

EFFORT_WEIGHT = 0.01
POSITION_FLOOR = 0.1  # m
ORIENTATION_FLOOR = 0.5  # rad
TRACK_COST_CAP = 1.0
BONUS_POSITION = 0.01  # m
BONUS_ORIENTATION = 0.02  # rad

TrackReading = tuple[Any, Sequence[Any], Any, Sequence[Any], float]
"""One track of one body after a step: whether the body has it (a bool, or one per sub-env),
its deviation (D or phi, first 3 entries read), the time left to the current goal, the course's
13 observation entries (start deviation 3, duration 1, next start 3, next duration 1, end
velocity 3, flags: has a track, is the last goal) and the floor of its scale (m or rad)."""


class StepScore:
    """What a reward mode scores after a step, for one env (floats) or N sub-envs (arrays):
    every track of every body in body order, position first (:data:`TrackReading`), the
    number of bodies, the clipped action's sum of squares and size, the goal bonuses of the
    tick, the failure flag and the steps the episode had left."""

    __slots__ = ("action_size", "bonus", "failed", "n_bodies", "square_sum", "steps_left", "tracks")

    def __init__(
        self, tracks: list[TrackReading], n_bodies: int, square_sum: Any, action_size: int,
        bonus: Any, failed: Any, steps_left: Any,
    ) -> None:  # fmt: skip
        self.tracks = tracks
        self.n_bodies = n_bodies
        self.square_sum = square_sum
        self.action_size = action_size
        self.bonus = bonus
        self.failed = failed
        self.steps_left = steps_left


class RewardMode:
    """A reward mode: :meth:`reward` of a :class:`StepScore` (module docstring). Subclasses
    write it with elementwise arithmetic and :mod:`sgc_env.paper.elementwise`'s branches so
    that one env and the batched env score alike; a mode keeps no state between steps."""

    name = "custom"

    def reward(self, step: StepScore) -> Any:
        """The step's reward: a float for one env, one per sub-env for the batched env."""
        raise NotImplementedError

    def __repr__(self) -> str:
        return f"{type(self).__name__}()"


REWARD_CLASSES: dict[str, type[RewardMode]] = {}


def reward_mode(cls: type[RewardMode]) -> type[RewardMode]:
    """Register a mode under its ``name`` (the ``reward=`` string that picks it)."""
    REWARD_CLASSES[cls.name] = cls
    return cls


def goal_bonus(events: Sequence[GoalEvent]) -> float:
    """The bonuses of the goals met this tick (the module docstring)."""
    total = 0.0
    for ev in events:
        if ev["position_error"] is not None:
            total += math.exp(-ev["position_error"] / BONUS_POSITION)
        if ev["orientation_error"] is not None:
            total += math.exp(-ev["orientation_error"] / BONUS_ORIENTATION)
    return total


def effort(step: StepScore) -> Any:
    """``0.01 mean(a^2)``, the effort term of every mode."""
    return EFFORT_WEIGHT * step.square_sum / step.action_size


def schedule_error(d: Sequence[Any], left: Any, c: Sequence[Any], floor: float) -> Any:
    """``|D - D_sched| / L`` (see the module docstring), uncapped."""
    ahead = left >= 0.0
    if ahead is True or ahead is not False and all_(ahead):  # one value inline: elementwise
        f = left / c[3]
        rx, ry, rz = c[0] * f, c[1] * f, c[2] * f
    elif not any_(ahead):
        rx, ry, rz = -c[8] * left, -c[9] * left, -c[10] * left
    else:
        f = left / c[3]
        rx = where(ahead, c[0] * f, -c[8] * left)
        ry = where(ahead, c[1] * f, -c[9] * left)
        rz = where(ahead, c[2] * f, -c[10] * left)
    ex, ey, ez = d[0] - rx, d[1] - ry, d[2] - rz
    scale = at_least(sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]), floor)
    return sqrt(ex * ex + ey * ey + ez * ez) / scale


def schedule_cost(d: Sequence[Any], left: Any, c: Sequence[Any], floor: float) -> Any:
    """``min(|D - D_sched| / L, 1)`` (see the module docstring)."""
    return at_most(schedule_error(d, left, c, floor), TRACK_COST_CAP)


def tracking_score(d: Sequence[Any], left: Any, c: Sequence[Any], floor: float) -> Any:
    """``1 / (1 + |D - D_sched| / L)``: 1 on the schedule, falling at every distance."""
    return 1.0 / (1.0 + schedule_error(d, left, c, floor))


def distance_cost(d: Sequence[Any], left: Any, c: Sequence[Any], floor: float) -> Any:
    """``|D| / L`` (uncapped)."""
    scale = at_least(sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]), floor)
    return sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) / scale


def tracks_of(task: GoalTask) -> list[TrackReading]:
    """The tracks of one env's task (every body's it has, position first)."""
    out: list[TrackReading] = []
    for i in range(task.n_bodies):
        if task.has_position[i]:
            out.append(
                (True, task.deviations[i], task.position_time_left[i], task.position_course[i],
                 POSITION_FLOOR)
            )  # fmt: skip
        if task.has_orientation[i]:
            out.append(
                (True, task.phi[i], task.orientation_time_left[i], task.orientation_course[i],
                 ORIENTATION_FLOOR)
            )  # fmt: skip
    return out


_SEQUENTIAL_SUM = sys.version_info < (3, 12)  # 3.12's sum() of floats is compensated


def square_sum(action: Any) -> Any:
    """``sum(x * x for x in action)`` of one action (floats), or of each row of an (N, size)
    array, summed as Python's ``sum`` does (left to right before 3.12)."""
    if not isinstance(action, np.ndarray):
        return sum([x * x for x in action])
    squares = action * action
    if _SEQUENTIAL_SUM:
        total = squares[:, 0].copy()
        for k in range(1, squares.shape[1]):
            total += squares[:, k]
        return total
    return np.array([sum(row) for row in squares.tolist()])


def track_costs(
    step: StepScore, cost: Callable[[Sequence[Any], Any, Sequence[Any], float], Any]
) -> tuple[Any, Any]:
    """The sum of ``cost`` over the tracks a body has, in track order, and the sum of the cap
    over them (the worst the costs can be, when ``cost`` is capped)."""
    total: Any = 0.0
    worst: Any = 0.0
    for has, d, left, course, floor in step.tracks:
        if has is False or has is not True and not any_(has):  # one value inline: elementwise
            continue
        value = cost(d, left, course, floor)
        if has is True or all_(has):
            total, worst = total + value, worst + TRACK_COST_CAP
        else:
            total = where(has, total + value, total)
            worst = where(has, worst + TRACK_COST_CAP, worst)
    return total, worst


def failure_charge(step: StepScore, reward: Any, worst: Any) -> Any:
    """``reward`` less, on a failure, every step left at the worst per-step reward
    (``worst / bodies + 0.01``)."""
    failed = step.failed
    if failed is False or failed is not True and not any_(failed):  # one value inline
        return reward
    return where(
        step.failed, reward - (worst / step.n_bodies + EFFORT_WEIGHT) * step.steps_left, reward
    )


@reward_mode
class ScheduleReward(RewardMode):
    """The default: distance from the on-schedule deviation (capped), effort, bonuses, and the
    failure charge."""

    name = "schedule"

    def reward(self, step: StepScore) -> Any:
        cost, worst = track_costs(step, schedule_cost)
        return failure_charge(step, -cost / step.n_bodies - effort(step) + step.bonus, worst)


@reward_mode
class DistanceReward(RewardMode):
    """The reward before the modes: ``|D| / L`` per track, effort, bonuses, no failure charge."""

    name = "distance"

    def reward(self, step: StepScore) -> Any:
        cost, _ = track_costs(step, distance_cost)
        return -cost / step.n_bodies - effort(step) + step.bonus


@reward_mode
class SparseReward(RewardMode):
    """Goal-tick bonuses and effort only; a failure charges the worst effort per step left."""

    name = "sparse"

    def reward(self, step: StepScore) -> Any:
        return failure_charge(step, -0.0 / step.n_bodies - effort(step) + step.bonus, 0.0)


@reward_mode
class TrackingReward(RewardMode):
    """The default of the ids' newest versions: ``mean_b sum_tracks 1 / (1 + x)`` with ``x =
    |D - D_sched| / L``, plus ``0.01 (1 - mean(a^2))`` and the goal bonuses; no failure charge.

    The same on-schedule error as ``schedule``, paid in a form a learner can climb: every step
    alive earns between 0 and the number of tracks, so leaving the workspace loses what the
    rest of the episode would have paid (no lump charge that a value function has to predict),
    and ``1 / (1 + x)`` falls at every distance (``schedule``'s ``min(x, 1)`` is flat beyond a
    course length, where an untrained body spends its first episodes). Undiscounted, it ranks
    policies that finish the episode as ``schedule`` does, up to a constant per scenario.
    """

    name = "tracking"

    def reward(self, step: StepScore) -> Any:
        score, _ = track_costs(step, tracking_score)
        return score / step.n_bodies + EFFORT_WEIGHT - effort(step) + step.bonus


REWARD_MODES: tuple[str, ...] = tuple(REWARD_CLASSES)


def make_reward(mode: object) -> RewardMode:
    """The mode ``mode`` names (one of :data:`REWARD_MODES`), or ``mode`` itself when it is a
    :class:`RewardMode`."""
    return choose("reward", "mode", mode, REWARD_CLASSES, RewardMode)
