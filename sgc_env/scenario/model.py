"""Scenario data model: bodies, goal sequences and kinematic props, as plain frozen data.

Frozen and hashable, so a resolved scenario can key caches (the plan check is cached on it).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from sgc_env.paper import quaternion as quat
from sgc_env.paper.end_rules import DEFAULT_END_RULE

__all__ = [
    "Body", "Goal", "Prop", "Quat", "Scenario", "ScenarioError", "Vec3", "goal_orientations",
    "grid_tick", "grid_time",
]  # fmt: skip

Vec3 = tuple[float, float, float]
Quat = tuple[float, float, float, float]


def grid_tick(t: float, frequency: int) -> int:
    """The control tick nearest to time ``t``: the one rounding of times to the grid."""
    return round(t * frequency)


def grid_time(t: float, frequency: int) -> float:
    """``t`` rounded to the nearest control tick (an exact multiple of ``1 / frequency``)."""
    return grid_tick(t, frequency) / frequency


class ScenarioError(ValueError):
    """A scenario is malformed; the message starts with the offending field path."""


@dataclass(frozen=True)
class Goal:
    """One goal: a point-to-nail part, an orientation part, or both, with a time.

    ``relative_rotation`` is a world-frame rotation vector applied to the previous orientation
    goal (or the initial orientation); it may be longer than pi (a somersault). ``nail_prop``
    binds the nail to a prop's position at the goal time (interception). ``critical`` defaults
    to "a time is given"; non-critical goals get their time from routing ``weight``.
    """

    nail: Vec3 | None = None
    point: Vec3 = (0.0, 0.0, 0.0)
    orientation: Quat | None = None
    relative_rotation: Vec3 | None = None
    time: float | None = None
    critical: bool | None = None
    weight: float = 1.0
    nail_prop: str | None = None

    @property
    def has_position(self) -> bool:
        return self.nail is not None or self.nail_prop is not None

    @property
    def has_orientation(self) -> bool:
        return self.orientation is not None or self.relative_rotation is not None

    @property
    def is_critical(self) -> bool:
        return self.time is not None if self.critical is None else bool(self.critical)


@dataclass(frozen=True)
class Body:
    """A rigid body driven by a force and a torque, with its goal sequence."""

    name: str
    shape: str = "sphere"
    size: tuple[float, ...] = (0.05,)
    mass: float = 1.0
    position: Vec3 = (0.0, 0.0, 0.0)
    orientation: Quat = (0.0, 0.0, 0.0, 1.0)
    linear_velocity: Vec3 = (0.0, 0.0, 0.0)
    angular_velocity: Vec3 = (0.0, 0.0, 0.0)
    color: tuple[float, float, float, float] = (0.2, 0.4, 0.85, 1.0)
    force_limit: float = 50.0
    torque_limit: float = 5.0
    goals: tuple[Goal, ...] = ()
    end_velocity: Vec3 | None = None
    end_angular_velocity: Vec3 | None = None
    collisions: bool = True

    @property
    def has_position_track(self) -> bool:
        return any(g.has_position for g in self.goals)

    @property
    def has_orientation_track(self) -> bool:
        return any(g.has_orientation for g in self.goals)


@dataclass(frozen=True)
class Prop:
    """A kinematic body on a scripted path: piecewise-linear ``waypoints`` ((t, (x, y, z)), ...)
    or, without waypoints, ``position + velocity * t``. Held at the ends of a waypoint path."""

    name: str
    shape: str = "sphere"
    size: tuple[float, ...] = (0.1,)
    color: tuple[float, float, float, float] = (0.9, 0.1, 0.1, 1.0)
    position: Vec3 = (0.0, 0.0, 0.0)
    velocity: Vec3 = (0.0, 0.0, 0.0)
    waypoints: tuple[tuple[float, Vec3], ...] = ()
    collisions: bool = False

    def position_at(self, t: float) -> np.ndarray:
        if not self.waypoints:
            return np.asarray(self.position, float) + np.asarray(self.velocity, float) * t
        times = [w[0] for w in self.waypoints]
        pts = np.asarray([w[1] for w in self.waypoints], float)
        return np.array([np.interp(t, times, pts[:, j]) for j in range(3)])


@dataclass(frozen=True)
class Scenario:
    """A whole scene. ``resolved`` is set by :func:`resolve_scenario` (all goal times filled).

    ``allow_saturation``: accept goals whose plan needs more force or torque than the limits
    (the actuators then saturate and goals may be missed); by default that is an error.
    """

    bodies: tuple[Body, ...]
    props: tuple[Prop, ...] = ()
    name: str = "scenario"
    gravity: Vec3 = (0.0, 0.0, -9.81)
    workspace: tuple[Vec3, Vec3] = ((-20.0, -20.0, -20.0), (20.0, 20.0, 20.0))
    margin: float = 0.25
    control_frequency: int = 60
    time_grid: str = "reject"
    end_velocity_rule: str = DEFAULT_END_RULE
    allow_saturation: bool = False
    resolved: bool = field(default=False, compare=False)

    def body_index(self, name: str) -> int:
        for i, b in enumerate(self.bodies):
            if b.name == name:
                return i
        raise KeyError(f"no body named {name!r}")


def goal_orientations(body: Body) -> list[Quat | None]:
    """Per goal, the orientation (xyzw) it asks for, or None for a goal without one: an
    absolute ``orientation`` as given, a ``relative_rotation`` ``r`` as ``Exp(r)`` applied to
    the previous orientation goal's target (or to the initial orientation). The one place
    relative rotations become goal quaternions (plain floats, as the env's tracks)."""
    out: list[Quat | None] = []
    previous: Quat = body.orientation
    for g in body.goals:
        if g.relative_rotation is not None:
            previous = quat.mul(quat.exp_normalized(g.relative_rotation), previous)
        elif g.orientation is not None:
            previous = g.orientation
        else:
            out.append(None)
            continue
        out.append(previous)
    return out
