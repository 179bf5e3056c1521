"""From next-tick targets to the force and torque that reach them (shared by all policies).

A model-based policy decides where a body's tracked point and orientation should be at the
next control tick; :func:`wrench_for_targets` turns that into the world force and torque that
put it there through PyBullet's integrator (:mod:`baselines.controllers.tracking`). The expert, the
dynamic-constraints and the minimum-jerk baselines differ only in how they choose targets.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from baselines.common.env_model import BodyModel, EnvModel
from baselines.common.observation_fields import BodyObservation
from baselines.controllers.tracking import (
    held_acceleration_for_position,
    simulate_rotation,
    torque_for_orientation,
)
from sgc_env.paper import quaternion as quat

__all__ = ["body_wrench", "wrench_for_targets"]

Vec3 = tuple[float, float, float]
Quat = tuple[float, float, float, float]


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
    the Newton-refined torque (goal ticks) instead of the once-corrected first guess.
    """
    force, torque = body_wrench(
        model, body, tuple(state.orientation.tolist()), tuple(state.angular_velocity.tolist()),
        tuple(state.linear_velocity.tolist()), tuple(state.point_offset.tolist()),
        None if point_displacement is None else tuple(np.asarray(point_displacement, float)),
        None if rotation_change is None else tuple(rotation_change.as_quat().tolist()),
        exact_rotation=exact_rotation,
    )  # fmt: skip
    return np.array(force), np.array(torque)


def body_wrench(
    model: EnvModel,
    body: BodyModel,
    orientation: Quat,
    angular_velocity: Vec3,
    linear_velocity: Vec3,
    point_offset: Vec3,
    point_displacement: Vec3 | None,
    rotation_change: Quat | None,
    *,
    exact_rotation: bool,
    refine: bool = True,
) -> tuple[Vec3, Vec3]:
    """:func:`wrench_for_targets` on plain-float tuples (quaternions ``(x, y, z, w)``).

    The expert calls this every control step, where numpy and scipy calls on 3-vectors would
    cost more than the arithmetic. ``refine=False`` skips the correction step of the torque
    between goals (see :func:`baselines.controllers.tracking.torque_for_orientation`).
    """
    h, n = model.sim_dt, model.substeps
    q = orientation
    if rotation_change is None:
        torque = (0.0, 0.0, 0.0)
        next_q = None
    else:
        next_q = quat.mul(rotation_change, q)
        torque = torque_for_orientation(
            q, angular_velocity, next_q, body.inertia, h, n, exact=exact_rotation, refine=refine
        )
    gx, gy, gz = model.gravity
    mass = body.mass
    if point_displacement is None:
        return (-mass * gx, -mass * gy, -mass * gz), torque
    if next_q is None:
        next_q = simulate_rotation(q, angular_velocity, torque, body.inertia, h, n)[0]
    ax, ay, az = quat.rotate(next_q, point_offset)
    bx, by, bz = quat.rotate(q, point_offset)
    dx, dy, dz = point_displacement
    vx, vy, vz = linear_velocity
    accel = held_acceleration_for_position  # per component: plain floats, no arrays
    return (
        mass * (float(accel(0.0, vx, dx - (ax - bx), h, n)) - gx),
        mass * (float(accel(0.0, vy, dy - (ay - by), h, n)) - gy),
        mass * (float(accel(0.0, vz, dz - (az - bz), h, n)) - gz),
    ), torque
