"""From next-tick targets to the force and torque that reach them (shared by all policies).

A model-based policy decides where a body's tracked point and orientation should be at the
next control tick; :func:`wrench_for_targets` turns that into the world force and torque that
put it there through PyBullet's integrator (:mod:`baselines.tracking`). The expert, the
dynamic-constraints and the minimum-jerk baselines differ only in how they choose targets.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from baselines.env_model import BodyModel, EnvModel
from baselines.tracking import (
    held_acceleration_for_position,
    simulate_rotation,
    torque_for_orientation,
)

__all__ = ["BodyObservation", "read_body", "wrench_for_targets"]

_TRACKS = ("position", "orientation")
_TRACK_FIELDS = (
    "deviation", "time_left", "course_start", "course_duration", "next_start",
    "next_duration", "end_velocity", "flags",
)  # fmt: skip


@dataclass(frozen=True)
class BodyObservation:
    """One body's observation block in double precision (float32 value + residual)."""

    orientation: np.ndarray
    angular_velocity: np.ndarray
    linear_velocity: np.ndarray
    point_offset: np.ndarray
    point_velocity: np.ndarray
    position: dict[str, np.ndarray]
    orientation_track: dict[str, np.ndarray]

    def track(self, name: str) -> dict[str, np.ndarray]:
        return self.position if name == "position" else self.orientation_track

    def has_goal_ahead(self, name: str, period: float) -> bool:
        """True while a goal of track ``name`` lies at least one tick ahead.

        Half a period of slack: on a goal's own tick the time left is zero up to rounding of
        the tick times, and that goal must count as reached, not as still ahead.
        """
        t = self.track(name)
        return bool(t["flags"][0] > 0.5 and t["time_left"][0] > 0.5 * period)


def read_body(model: EnvModel, observation: np.ndarray, body: int) -> BodyObservation:
    """Extract body ``body``'s fields, adding each ``<field>_residual`` where the layout has one."""
    layout = model.layout
    obs = np.asarray(observation, dtype=np.float64)

    def field(name: str) -> np.ndarray:
        value = obs[layout.body_slice(body, name)]
        if layout.has_body_field(f"{name}_residual"):
            value = value + obs[layout.body_slice(body, f"{name}_residual")]
        return value

    q = field("orientation")
    tracks = {
        track: {name: field(f"{track}_{name}") for name in _TRACK_FIELDS} for track in _TRACKS
    }
    return BodyObservation(
        orientation=q / np.linalg.norm(q),
        angular_velocity=field("angular_velocity"),
        linear_velocity=field("linear_velocity"),
        point_offset=field("point_offset"),
        point_velocity=field("point_velocity"),
        position=tracks["position"],
        orientation_track=tracks["orientation"],
    )


def wrench_for_targets(
    model: EnvModel,
    body: BodyModel,
    state: BodyObservation,
    *,
    point_displacement: np.ndarray | None,
    rotation_change: Rotation | None,
    exact_rotation: bool,
) -> tuple[np.ndarray, np.ndarray]:
    """World force and torque that move the body as asked over the next control period.

    ``point_displacement``: how far the tracked point must move (``D_next - D``); None lets
    the centre of mass coast (gravity compensated). ``rotation_change``: world rotation from
    now to the next tick; None applies no torque (free rotation). ``exact_rotation`` asks for
    the Newton-refined torque (goal ticks) instead of the closed-form first guess.
    """
    h, n = model.sim_dt, model.substeps
    q = state.orientation
    rotation = Rotation.from_quat(q)
    if rotation_change is None:
        torque = np.zeros(3)
        next_rotation = Rotation.from_quat(
            simulate_rotation(q, state.angular_velocity, (0.0, 0.0, 0.0), body.inertia, h, n)[0]
        )
    else:
        next_rotation = rotation_change * rotation
        torque = np.array(
            torque_for_orientation(
                q, state.angular_velocity, next_rotation.as_quat(), body.inertia, h, n,
                exact=exact_rotation,
            )
        )
    if point_displacement is None:
        accel = np.zeros(3)
    else:
        offset = state.point_offset
        offset_move = next_rotation.apply(offset) - rotation.apply(offset)
        com_move = np.asarray(point_displacement, dtype=float) - offset_move
        accel = held_acceleration_for_position(np.zeros(3), state.linear_velocity, com_move, h, n)
    force = body.mass * (accel - np.asarray(model.gravity))
    return force, torque
