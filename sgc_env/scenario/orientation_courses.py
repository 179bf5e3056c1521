"""An orientation track's goal rotations, paces and somersault splits, computed once per track.

Why a module of its own: a random three-rod draw computes them for the planner-free bound
(:mod:`sgc_env.scenes.course_bound`) and, for each rod it keeps, the env computes them again
when it compiles the rod's tracks (:mod:`sgc_env.envs.tracks`): a fifth of a reset. Both now
call :func:`orientation_courses`, memoised on its (hashable, plain-float) inputs, so the env's
call for a kept rod is a cache hit; the values are those of the ``sgc_env.paper.orientation``
functions it calls, so planner, bound and env still split a somersault alike.

Loaded on first use only by the modules above: ``sgc_env.paper.orientation`` imports scipy.
"""

from __future__ import annotations

from functools import lru_cache
from typing import NamedTuple

from sgc_env.paper.orientation import goal_rotations, neighbour_paces, split_rotation

__all__ = ["OrientationCourses", "orientation_courses"]

Vec3 = tuple[float, float, float]
Quat = tuple[float, float, float, float]
Split = tuple[tuple[Vec3, float], ...]

CACHE_SIZE = 64
"""Tracks remembered: a batched reset draws every sub-env's scene before the next one, and
a rejected rod's entry is never asked for again, so a few dozen are plenty."""


class OrientationCourses(NamedTuple):
    """Per orientation goal: its rotation from the previous goal (``goal_rotations``), its
    ``(rate_in, rate_out)`` (``neighbour_paces``) and, for a relative rotation, its
    ``split_rotation`` pieces on the control grid (None for an absolute orientation, and where
    the split is refused: call ``split_rotation`` then for the error naming the goal)."""

    rotations: tuple[Vec3, ...]
    paces: tuple[tuple[float, float], ...]
    splits: tuple[Split | None, ...]


@lru_cache(maxsize=CACHE_SIZE)
def orientation_courses(
    start: Quat,
    goals: tuple[tuple[Quat | None, Vec3 | None], ...],
    times: tuple[float, ...],
    angular_velocity: Vec3,
    end_angular_velocity: Vec3 | None,
    frequency: int,
) -> OrientationCourses:
    """The courses of an orientation track from ``start`` (xyzw) through ``goals``
    (``(orientation, relative_rotation)`` each) at ``times``, split on the ticks of
    ``frequency`` Hz (see :class:`OrientationCourses`)."""
    rotations = goal_rotations(start, goals)
    paces = neighbour_paces(rotations, times, angular_velocity, end_angular_velocity)
    splits: list[Split | None] = []
    t_prev = 0.0
    for (_, relative), rotation, t, (rate_in, rate_out) in zip(
        goals, rotations, times, paces, strict=True
    ):
        split = None
        if relative is not None:
            try:
                split = tuple(
                    split_rotation(
                        rotation, t_prev, t, frequency, rate_in=rate_in, rate_out=rate_out
                    )
                )
            except ValueError:
                split = None
        splits.append(split)
        t_prev = t
    return OrientationCourses(tuple(rotations), tuple(paces), tuple(splits))
