"""Per-body goal tracks compiled from a resolved scenario (the data :mod:`.task` runs on).

A body's goals split into a position track (goals with a nail) and an orientation track
(goals with an orientation part). Everything the observation needs about the current and next
course is precomputed here once per scenario, so a control step only indexes arrays.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from sgc_env.paper import quaternion as quat
from sgc_env.paper.orientation import split_rotation
from sgc_env.scenario import Body, Scenario
from sgc_env.scenario.orientation_courses import orientation_courses

__all__ = ["BodyTracks", "Track", "compile_tracks"]


@dataclass
class Track:
    """One track of one body (position or orientation), arrays indexed by track goal."""

    goal_ids: np.ndarray  # index of each track goal in the body's goal list
    ticks: np.ndarray  # control tick of each goal (int)
    times: np.ndarray
    targets: np.ndarray  # nails (m, 3) or goal quaternions (m, 4)
    points: np.ndarray  # body points (m, 3); zeros for orientation
    course_start: np.ndarray  # (m, 3) nominal deviation at the start of each course
    durations: np.ndarray  # (m,)
    next_start: np.ndarray  # (m, 3); zeros for the last
    next_duration: np.ndarray  # (m,)
    end_velocity: np.ndarray  # (3,)
    via: np.ndarray = field(default_factory=lambda: np.zeros(0, bool))  # inserted sub-goals

    @property
    def size(self) -> int:
        return len(self.ticks)


@dataclass
class BodyTracks:
    position: Track | None
    orientation: Track | None


def _finish(track: Track) -> Track:
    m = track.size
    track.durations = np.diff(np.concatenate(([0.0], track.times)))
    track.next_start = np.zeros((m, 3))
    track.next_duration = np.zeros(m)
    if m > 1:
        track.next_start[:-1] = track.course_start[1:]
        track.next_duration[:-1] = track.durations[1:]
    return track


def _position_track(body: Body, freq: int) -> Track | None:
    ids = [j for j, g in enumerate(body.goals) if g.has_position]
    if not ids:
        return None
    goals = [body.goals[j] for j in ids]
    times = np.array([float(g.time) for g in goals])  # type: ignore[arg-type]
    nails = np.array([g.nail for g in goals], float)
    points = np.array([g.point for g in goals], float)
    start_point = np.add(body.position, quat.rotate(body.orientation, points[0]))
    prev = np.vstack((start_point, nails[:-1]))
    course_start = prev - nails
    if body.end_velocity is not None:
        end_v = np.asarray(body.end_velocity, float)
    else:
        end_v = (nails[-1] - prev[-1]) / (times[-1] - (times[-2] if len(times) > 1 else 0.0))
    track = Track(
        np.array(ids), np.rint(times * freq).astype(int), times, nails, points, course_start,
        np.zeros(0), np.zeros(0), np.zeros(0), end_v,
    )  # fmt: skip
    return _finish(track)


def _orientation_track(body: Body, freq: int) -> Track | None:
    ids = [j for j, g in enumerate(body.goals) if g.has_orientation]
    if not ids:
        return None
    goal_ids, quats, starts, times, via = [], [], [], [], []
    prev_q = tuple(body.orientation)
    prev_t = 0.0
    goals = [body.goals[j] for j in ids]
    # Memoised: a random family's feasibility bound computed the same for the body it drew.
    courses = orientation_courses(
        prev_q, tuple((g.orientation, g.relative_rotation) for g in goals),
        tuple(float(g.time) for g in goals),  # type: ignore[arg-type]
        body.angular_velocity, body.end_angular_velocity, freq,
    )  # fmt: skip
    after_split = False
    for k, (j, rotation, split) in enumerate(
        zip(ids, courses.rotations, courses.splits, strict=True)
    ):
        g = goals[k]
        t = float(g.time)  # type: ignore[arg-type]
        if g.relative_rotation is None:
            q = tuple(map(float, g.orientation))  # type: ignore[arg-type]
            # goal_rotations measured the same step from the same quaternion, unless a split
            # relative rotation came before (its pieces compose to other floats).
            step = quat.log(quat.mul_conjugate(q, prev_q)) if after_split else rotation
            prev_q, after_split = q, False
            goal_ids.append(j)
            quats.append(q)
            starts.append((-step[0], -step[1], -step[2]))
            times.append(t)
            via.append(False)
        else:
            if split is None:  # refused: split again for the error that names the goal
                rate_in, rate_out = courses.paces[k]
                split = tuple(split_rotation(
                    g.relative_rotation, prev_t, t, freq, f"{body.name}.goals[{j}]",
                    rate_in=rate_in, rate_out=rate_out,
                ))  # fmt: skip
            for i, (step, end) in enumerate(split, 1 - len(split)):  # i == 0: the last piece
                prev_q = quat.mul(quat.exp_normalized(step), prev_q)
                goal_ids.append(j)
                quats.append(prev_q)
                starts.append((-step[0], -step[1], -step[2]))
                times.append(end)
                via.append(i != 0)
            after_split = True
        prev_t = t
    end_w = (
        np.zeros(3) if body.end_angular_velocity is None else np.asarray(body.end_angular_velocity)
    )
    times_arr = np.array(times)
    track = Track(
        np.array(goal_ids), np.rint(times_arr * freq).astype(int), times_arr, np.array(quats),
        np.zeros((len(goal_ids), 3)),
        np.array(starts, float), np.zeros(0), np.zeros(0), np.zeros(0), end_w.astype(float),
        np.array(via, bool),
    )  # fmt: skip
    return _finish(track)


def compile_tracks(scenario: Scenario) -> list[BodyTracks]:
    """Tracks of every body of a resolved scenario."""
    if not scenario.resolved:
        raise ValueError("compile_tracks needs a resolved scenario (see resolve_scenario)")
    f = scenario.control_frequency
    return [BodyTracks(_position_track(b, f), _orientation_track(b, f)) for b in scenario.bodies]
