"""The env's reward: one :class:`RewardMode` class per mode, each with one method.

A mode's :meth:`RewardMode.reward` scores a :class:`StepScore`, the same for one env (floats)
and for the batched env (arrays over sub-envs): its arithmetic is elementwise and its branches
go through :mod:`sgc_env.paper.elementwise`, so both envs run this code and agree bit for bit.
``gym.make(id, reward=...)`` and ``gym.make_vec(id, n, reward=...)`` take a mode's name
(:data:`REWARD_MODES`) or a :class:`RewardMode` instance, a mode of the caller's own. Adding a
mode is one subclass here, registered by :func:`reward_mode`.

A mode reads what the observation carries (per body and track: the deviation ``D``, the time
left, the course's start deviation ``D_i(0)`` and duration ``T_i``, the end velocity after the
last goal), the clipped action and the goal-tick events, so a reward is a function of what the
agent observes plus the goal errors of that tick.

``tracking`` (every id's), per step::

    r = mean_b sum_tracks 1 / (1 + x) + 0.01 (1 - mean(a^2)) + bonuses
    x = |D - D_sched| / L        D_sched: the course on schedule (:mod:`sgc_env.envs.schedule`)
    bonuses = sum over goals met this tick of exp(-|D| / 0.01 m) (+ exp(-|phi| / 0.02 rad))

with ``L = max(|D_i(0)|, 0.1 m)`` and, for orientation, ``phi`` in place of ``D`` and
``L = max(|phi_i(0)|, 0.5 rad)``. Why this reference: ``D_sched`` is the paper's behaviour
equation ``D'' - 2a D' + (a^2 + b^2) D = 0`` with end conditions ``D(T) = 0, D'(T) = -k D0/T``
in its neutral member (``k = 1``, ``a = b = 0``): the course travelled at its average speed, on
schedule. It depends only on the course (``D_i(0)``, ``T_i``) and the clock, never on the
agent's own state, so the score is highest only for a body that is where the course says it
should be *now*: arriving early and hovering on the nail scores less, as does arriving late, and
the tick's bonus pays only for exactness on the tick. The SGC expert departs from the neutral
course only by its smooth start (it enters each course with the previous course's end velocity),
so it earns near the maximum. Why this form: every step alive earns between 0 and the number of
tracks, so leaving the workspace loses what the rest of the episode would have paid (no lump
charge that a value function has to predict), and ``1 / (1 + x)`` falls at every distance, so a
learner far off its schedule still sees a slope.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from sgc_env.paper.elementwise import all_, any_, at_least, sqrt, where

from .choices import choose
from .schedule import on_schedule

if TYPE_CHECKING:
    from .task import GoalEvent, GoalTask

__all__ = [
    "EFFORT_WEIGHT",
    "REWARD_MODES",
    "RewardMode",
    "StepScore",
    "TrackingReward",
    "TrackReading",
    "effort",
    "goal_bonus",
    "make_reward",
    "reward_mode",
    "schedule_error",
    "square_sum",
    "track_costs",
    "tracking_score",
    "tracks_of",
]

EFFORT_WEIGHT = 0.01
POSITION_FLOOR = 0.1  # m
ORIENTATION_FLOOR = 0.5  # rad
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
    """``|D - D_sched| / L`` (see the module docstring), uncapped: ``c`` is the track's course
    entries (start, duration, next start and duration, end velocity, flags)."""
    (rx, ry, rz), _, _, _ = on_schedule(c[0:3], c[3], c[8:11], left)
    ex, ey, ez = d[0] - rx, d[1] - ry, d[2] - rz
    scale = at_least(sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]), floor)
    return sqrt(ex * ex + ey * ey + ez * ez) / scale


def tracking_score(d: Sequence[Any], left: Any, c: Sequence[Any], floor: float) -> Any:
    """``1 / (1 + |D - D_sched| / L)``: 1 on the schedule, falling at every distance."""
    return 1.0 / (1.0 + schedule_error(d, left, c, floor))


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
) -> Any:
    """The sum of ``cost`` over the tracks a body has, in track order."""
    total: Any = 0.0
    for has, d, left, course, floor in step.tracks:
        if has is False or has is not True and not any_(has):  # one value inline: elementwise
            continue
        value = cost(d, left, course, floor)
        total = total + value if has is True or all_(has) else where(has, total + value, total)
    return total


@reward_mode
class TrackingReward(RewardMode):
    """Every id's reward: ``mean_b sum_tracks 1 / (1 + x)`` with ``x = |D - D_sched| / L``,
    plus ``0.01 (1 - mean(a^2))`` and the goal bonuses (module docstring)."""

    name = "tracking"

    def reward(self, step: StepScore) -> Any:
        score = track_costs(step, tracking_score)
        return score / step.n_bodies + EFFORT_WEIGHT - effort(step) + step.bonus


REWARD_MODES: tuple[str, ...] = tuple(REWARD_CLASSES)


def make_reward(mode: object) -> RewardMode:
    """The mode ``mode`` names (one of :data:`REWARD_MODES`), or ``mode`` itself when it is a
    :class:`RewardMode`."""
    return choose("reward", "mode", mode, REWARD_CLASSES, RewardMode)
