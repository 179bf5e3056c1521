"""The measurement rule: where each body's tracked point is and how far it is from its goals.

Written once for one env and for many: every argument is a float (one body of one env, the
single env's loop) or an array over sub-envs (and bodies) of the batched env, and the result
has the same form (:mod:`sgc_env.paper.elementwise`; a float 0 stands for zeros everywhere).
``D = world point - nail``, ``D' = v + omega x r`` with ``r`` the point's lever arm, ``phi``
the rotation from the goal orientation to the body's, unwrapped next to its previous value,
and the times left to the current goals. A body without a position track measures ``D = 0``
and time left 0; one without an orientation track keeps its ``phi`` (its first course's
start) and time left 0.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from sgc_env.paper.elementwise import all_, any_, where, where3
from sgc_env.paper.quaternion import log, mul_conjugate, rotate, unwrap_rotvec

Vec = Sequence[Any]  # components: floats for one env, arrays for the batch

__all__ = ["Measured", "measure"]

_ZERO6 = (0.0,) * 6

Measured = tuple[Any, Any, Any, Any, Any]
"""(tracked point 3, deviation D and D' 6, position time left, phi 3, orientation time left)."""


def measure(
    state: Vec, time: Any, offset: Vec, has_offset: Any, nail: Vec, has_position: Any,
    position_time: Any, goal_quaternion: Vec, has_orientation: Any, orientation_time: Any,
    phi: Vec,
) -> Measured:  # fmt: skip
    """One body's measurement (module docstring); ``state`` is (position, orientation xyzw,
    velocity, angular velocity), each a tuple of components."""
    pos, orn, lin, ang = state
    # "x is True or x is not False and any_(x)": one value tested inline (sgc_env.paper.elementwise)
    if has_offset is True or has_offset is not False and any_(has_offset):
        lever: Any = rotate(orn, offset)
        point = (pos[0] + lever[0], pos[1] + lever[1], pos[2] + lever[2])
        if has_offset is not True and not all_(has_offset):
            lever, point = where3(has_offset, lever, offset), where3(has_offset, point, pos)
    else:
        lever, point = offset, pos
    if has_position is True or has_position is not False and any_(has_position):
        wx, wy, wz = ang
        rx, ry, rz = lever
        deviation = (
            point[0] - nail[0], point[1] - nail[1], point[2] - nail[2],
            lin[0] + wy * rz - wz * ry, lin[1] + wz * rx - wx * rz, lin[2] + wx * ry - wy * rx,
        )  # fmt: skip
        left = position_time - time
        if has_position is not True and not all_(has_position):
            deviation = tuple(where(has_position, d, 0.0) for d in deviation)
            left = where(has_position, left, 0.0)
    else:
        deviation, left = _ZERO6, 0.0
    if has_orientation is True or has_orientation is not False and any_(has_orientation):
        new = unwrap_rotvec(log(mul_conjugate(orn, goal_quaternion)), phi)
        orientation_left = orientation_time - time
        if has_orientation is not True and not all_(has_orientation):
            new = where3(has_orientation, new, phi)
            orientation_left = where(has_orientation, orientation_left, 0.0)
        phi = new
    else:
        orientation_left = 0.0
    return point, deviation, left, phi, orientation_left
