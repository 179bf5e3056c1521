"""The goal-tracking task: which goal each body is on, its deviation from it, goal events.

The env's three parts follow panda-gym: the :class:`~sgc_env.simulator.Simulator` moves bodies,
this :class:`GoalTask` judges them against the scenario's goals, and
:class:`~sgc_env.envs.sgc_env.SGCEnv` joins the two with the observation layout. The task owns
the compiled tracks, the current goal of every track, the deviations D, D' and the unwrapped
rotation deviation phi, the goal events of a tick and the goal-conditioned view (achieved and
desired goal) that HER relabels. It picks no reward (the env scores its mode,
:mod:`sgc_env.envs.rewards`) and never calls PyBullet: it is handed the bodies' states.

The per-step work is the measurement rule (:mod:`.measure`) on Python tuples, not numpy: for a
few bodies that is several times cheaper (``sgc bench env``). The batched env runs the
same rule on arrays over its sub-envs and moves a sub-env to its next goals with this class's
:meth:`GoalTask.advance` (goal ticks are rare).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TypedDict

import numpy as np

from sgc_env.observation import float32_residuals
from sgc_env.scenario import Scenario
from sgc_env.simulator import BodyReading

from .measure import measure
from .tracks import BodyTracks, Track, compile_tracks

__all__ = [
    "BodyReading",
    "GoalEvent",
    "GoalTask",
    "TaskCounters",
]

_ZERO3 = (0.0, 0.0, 0.0)
_ZERO13 = (0.0,) * 13


class GoalEvent(TypedDict):
    """A goal whose tick this is: the errors are |D| and the angle between the body and the goal
    orientation (in [0, pi]) at that tick (None for a part the goal does not have)."""

    body: int
    goal: int
    time: float
    position_error: float | None
    orientation_error: float | None


class TaskCounters(TypedDict):
    """What :meth:`GoalTask.counters` saves and :meth:`GoalTask.restore` reads back."""

    pos_idx: list[int]
    ori_idx: list[int]
    phi: list[list[float]]


def rotation_angle(phi: Sequence[float]) -> float:
    """The angle (in [0, pi]) between the body and the goal orientation: ``|phi|`` folded,
    because the unwrapped deviation can be longer than pi (7.35 rad is 1.07 rad away)."""
    angle = math.sqrt(phi[0] ** 2 + phi[1] ** 2 + phi[2] ** 2) % math.tau
    return min(angle, math.tau - angle)


def _course_fields(track: Track, k: int) -> tuple[float, ...]:
    """The 13 static observation entries of a track's course ``k``: course start and duration,
    next start and duration, end velocity (last goal only) and the two flags."""
    last = k == track.size - 1
    end = tuple(track.end_velocity) if last else _ZERO3
    return (
        *track.course_start[k].tolist(), float(track.durations[k]),
        *track.next_start[k].tolist(), float(track.next_duration[k]), *end, 1.0, float(last),
    )  # fmt: skip


def _with(array: np.ndarray, i: int, value: int) -> np.ndarray:
    """A copy with one entry changed: infos handed out earlier keep their goal indices."""
    out = array.copy()
    out[i] = value
    return out


class GoalTask:
    """Goal tracking of every body of one resolved scenario (see the module docstring).

    Per step the env calls :meth:`measure` with the bodies' states, then :meth:`advance` on a
    tick where a goal falls (:attr:`next_event`), then scores its reward mode on this task's
    tracks (the env owns the reward: this module never picks one). After
    :meth:`measure` the public lists hold, per body: :attr:`points` (world position of the
    tracked point), :attr:`deviations` (D and D', zeros without a position track), :attr:`phi`
    (unwrapped rotation deviation), :attr:`position_time_left`, :attr:`orientation_time_left`.
    """

    def __init__(self, scenario: Scenario) -> None:
        self.tracks: list[BodyTracks] = compile_tracks(scenario)
        self.n_bodies = len(self.tracks)
        self.dt = 1.0 / scenario.control_frequency
        self.has_position = [bt.position is not None for bt in self.tracks]
        self.has_orientation = [bt.orientation is not None for bt in self.tracks]
        n = self.n_bodies
        self.offsets: list[tuple[float, ...]] = [_ZERO3] * n
        self.has_offset = [False] * n
        self.offset_residuals: list[list[float]] = [[0.0, 0.0, 0.0]] * n
        self.nails: list[tuple[float, ...]] = [_ZERO3] * n
        self.goal_quaternions: list[tuple[float, ...]] = [(0.0, 0.0, 0.0, 1.0)] * n
        self.position_goal_time = [0.0] * n
        self.orientation_goal_time = [0.0] * n
        self.position_course: list[tuple[float, ...]] = [()] * n
        self.orientation_course: list[tuple[float, ...]] = [()] * n
        self.goal_index = np.full(n, -1)
        self.orientation_goal_index = np.full(n, -1)
        self.points: list[tuple[float, ...]] = []
        self.deviations: list[tuple[float, ...]] = []
        self.position_time_left: list[float] = []
        self.orientation_time_left: list[float] = []
        self.time = 0.0
        self.reset()

    # ---------------------------------------------------------------- goal bookkeeping

    def reset(self) -> None:
        """Every track back on its first goal, phi on its first course's start."""
        n = self.n_bodies
        self.pos_idx = [0] * n
        self.ori_idx = [0] * n
        self.phi: list[Sequence[float]] = [
            tr.orientation.course_start[0].tolist() if tr.orientation else [0.0] * 3
            for tr in self.tracks
        ]
        self._refresh(0)

    def counters(self) -> TaskCounters:
        return {
            "pos_idx": list(self.pos_idx),
            "ori_idx": list(self.ori_idx),
            "phi": [list(p) for p in self.phi],
        }

    def restore(self, counters: TaskCounters, tick: int) -> None:
        """Return to :meth:`counters`' goals; ``tick`` is the env's tick at that point."""
        self.pos_idx = list(counters["pos_idx"])
        self.ori_idx = list(counters["ori_idx"])
        self.phi = [list(p) for p in counters["phi"]]
        self._refresh(tick)

    def _refresh(self, tick: int) -> None:
        for i in range(self.n_bodies):
            self._write_static(i)
        self.next_event = self._first_pending_tick(tick)

    def _write_static(self, i: int) -> None:
        """Cache what changes only when a body's current goal changes (as Python tuples)."""
        tr = self.tracks[i].position
        if tr is not None:
            k = self.pos_idx[i]
            self.offsets[i] = tuple(tr.points[k].tolist())
            self.has_offset[i] = self.offsets[i] != _ZERO3
            self.offset_residuals[i] = float32_residuals(self.offsets[i])
            self.nails[i] = tuple(tr.targets[k].tolist())
            self.position_goal_time[i] = float(tr.times[k])
            self.position_course[i] = _course_fields(tr, k)
            self.goal_index = _with(self.goal_index, i, int(tr.goal_ids[k]))
        else:
            self.offsets[i] = _ZERO3
            self.has_offset[i] = False
            self.offset_residuals[i] = [0.0, 0.0, 0.0]
            self.position_course[i] = _ZERO13
        to = self.tracks[i].orientation
        if to is not None:
            k = self.ori_idx[i]
            self.goal_quaternions[i] = tuple(to.targets[k].tolist())
            self.orientation_goal_time[i] = float(to.times[k])
            self.orientation_course[i] = _course_fields(to, k)
            self.orientation_goal_index = _with(self.orientation_goal_index, i, int(to.goal_ids[k]))
        else:
            self.orientation_course[i] = _ZERO13

    def _first_pending_tick(self, tick: int) -> int:
        """The earliest goal tick after ``tick`` (-1 when none is left)."""
        ticks = []
        for j, bt in enumerate(self.tracks):
            if bt.position is not None:
                ticks.append(int(bt.position.ticks[self.pos_idx[j]]))
            if bt.orientation is not None:
                ticks.append(int(bt.orientation.ticks[self.ori_idx[j]]))
        ahead = [k for k in ticks if k > tick]
        return min(ahead) if ahead else -1

    # ---------------------------------------------------------------- per step

    def measure(self, states: Sequence[BodyReading], time: float) -> None:
        """Deviations of every body from its current goals at ``time`` (see the class), by the
        measurement rule of both envs (:func:`sgc_env.envs.measure.measure`)."""
        offsets, has_offset, nails, phis = self.offsets, self.has_offset, self.nails, self.phi
        has_pos, has_ori = self.has_position, self.has_orientation
        ptime, otime, goal_q = (
            self.position_goal_time,
            self.orientation_goal_time,
            self.goal_quaternions,
        )
        points = []
        deviations = []
        ptls = []
        otls = []
        for i, state in enumerate(states):
            point, deviation, ptl, phis[i], otl = measure(
                state, time, offsets[i], has_offset[i], nails[i], has_pos[i], ptime[i],
                goal_q[i], has_ori[i], otime[i], phis[i],
            )  # fmt: skip
            points.append(point)
            deviations.append(deviation)
            ptls.append(ptl)
            otls.append(otl)
        self.points = points
        self.deviations = deviations
        self.position_time_left = ptls
        self.orientation_time_left = otls
        self.time = time

    def advance(self, tick: int) -> tuple[list[GoalEvent], bool]:
        """Record the goals whose tick is ``tick`` (from the last :meth:`measure`), then move
        their tracks to the next goals. Returns the events and whether any goal changed (the
        deviations must then be measured again)."""
        events: list[GoalEvent] = []
        time = tick * self.dt
        any_changed = False
        for i, bt in enumerate(self.tracks):
            changed = False
            hits: dict[int, GoalEvent] = {}
            tr, to = bt.position, bt.orientation
            if tr is not None and tr.ticks[self.pos_idx[i]] == tick:
                k = self.pos_idx[i]
                d = np.array(self.deviations[i][:3])
                g = int(tr.goal_ids[k])
                hits[g] = {
                    "body": i,
                    "goal": g,
                    "time": time,
                    "position_error": float(math.sqrt(d @ d)),
                    "orientation_error": None,
                }
                if k < tr.size - 1:
                    self.pos_idx[i] = k + 1
                    changed = True
            if to is not None and to.ticks[self.ori_idx[i]] == tick:
                k = self.ori_idx[i]
                phi = self.phi[i]
                g = int(to.goal_ids[k])
                if not to.via[k]:
                    ev = hits.setdefault(
                        g,
                        {
                            "body": i,
                            "goal": g,
                            "time": time,
                            "position_error": None,
                            "orientation_error": None,
                        },
                    )
                    ev["orientation_error"] = rotation_angle(phi)
                if k < to.size - 1:
                    self.ori_idx[i] = k + 1
                    start = to.course_start[k + 1]
                    self.phi[i] = (phi[0] + start[0], phi[1] + start[1], phi[2] + start[2])
                    changed = True
            for g in sorted(hits):
                events.append(hits[g])
            if changed:
                self._write_static(i)
                any_changed = True
        self.next_event = self._first_pending_tick(tick)
        return events, any_changed

    # ---------------------------------------------------------------- goal-conditioned view

    def achieved_goal(self, body: int = 0) -> np.ndarray:
        """The tracked point of ``body`` and the time of the last :meth:`measure` (float32)."""
        return np.array([*self.points[body], self.time], dtype=np.float32)

    def desired_goal(self, body: int = 0) -> np.ndarray:
        """The nail of ``body``'s current position goal and that goal's time (float32)."""
        tr = self.tracks[body].position
        if tr is None:
            raise ValueError(f"body {body} has no position goals, so no desired goal")
        k = self.pos_idx[body]
        return np.array([*tr.targets[k], tr.times[k]], dtype=np.float32)
