"""The ``"matched"`` end velocities of a scenario, keyed by what the expert observes.

The matched rule (:mod:`sgc_env.paper.matched`) solves every interior end velocity of a track
at once, which a stateless expert cannot do from the current and the next course alone. The
expert therefore reads the scenario once per episode (as the env compiles it) and looks each
course up by its observation entries: course start, duration, next start and next duration,
as float32, exactly as the observation carries them. A state of that episode, visited or
not (DAgger queries), finds its course; a course of another scenario does not, and the expert
then falls back to the tangent rule (:class:`baselines.controllers.expert.SGCExpert`).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from sgc_env.envs.tracks import Track, compile_tracks
from sgc_env.paper import quaternion as quat
from sgc_env.scenario import Scenario

__all__ = ["EXPERT_RULES", "course_key", "course_row", "matched_table"]

EXPERT_RULES: tuple[str, ...] = ("tangent", "paper", "matched", "smooth")
"""End rules the expert plays: the scenario's two (:data:`sgc_env.paper.end_rules.END_RULES`)
and ``"matched"`` and ``"smooth"`` (:mod:`baselines.controllers.smooth_table`), which need the
scenario's whole tracks."""

MatchedTable = dict[tuple[float, ...], tuple[tuple[float, float, float], bool]]
"""Course key -> (end velocity, whether it was solved rather than the tangent rule's)."""


def course_key(values: Sequence[float]) -> tuple[float, ...]:
    """The lookup key of a course: its first 8 observation entries, as float32 values."""
    return tuple(np.asarray(values[:8], np.float32).tolist())


def course_row(track: Track, k: int) -> list[float]:
    """Course ``k``'s first 8 observation entries as the env compiles them (see
    :func:`course_key`)."""
    return [*track.course_start[k], track.durations[k], *track.next_start[k],
            track.next_duration[k]]  # fmt: skip


def matched_table(scenario: Scenario) -> MatchedTable:
    """Course key -> matched end velocity (world) of every interior course of every track, and
    whether its track was solved (else it holds the tangent rule's velocities)."""
    from sgc_env.paper.matched import matched_end_velocities  # scipy.optimize: only when used

    table: MatchedTable = {}
    for body, tracks in zip(scenario.bodies, compile_tracks(scenario), strict=True):
        omega = np.asarray(body.angular_velocity, float)
        for track, orientation in ((tracks.position, False), (tracks.orientation, True)):
            if track is None or track.size < 2:
                continue
            if orientation:
                start = omega
            else:  # the tracked point's velocity: v + omega x R r
                arm = quat.rotate(body.orientation, track.points[0])
                start = np.asarray(body.linear_velocity, float) + np.cross(omega, arm)
            ends = matched_end_velocities(
                track.course_start, track.durations, start, track.end_velocity,
                orientation=orientation,
            )  # fmt: skip
            for k in range(track.size - 1):
                v = ends.velocities[k]
                velocity = (float(v[0]), float(v[1]), float(v[2]))
                table[course_key(course_row(track, k))] = (velocity, ends.solved)
    return table
