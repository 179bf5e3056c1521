"""The demo's camera: shots keyed by time, eased from one to the next, as the paper's plates
change viewpoint.

A shot says where the camera looks (``look_at``), from how far, and from which side (yaw and
pitch in PyBullet's orbit convention). Between two key times the camera eases (smoothstep) so
that the video never cuts; the plates are taken from whichever shot is on. The easing and the
projection are :mod:`sgc_env.render.camera`'s, shared with ``env.render()``.
"""

from __future__ import annotations

from collections.abc import Sequence

from sgc_env.render.camera import Shot, View
from sgc_env.render.camera import camera_at as _eased

__all__ = ["DEMO_SHOTS", "Shot", "View", "camera_at"]

DEMO_SHOTS: tuple[Shot, ...] = (
    Shot(0.0, (-7.0, 0.0, 3.0), 9.0, 32.0, -12.0),  # the launch, seen from ahead: board behind
    Shot(1.3, (-5.5, 0.0, 3.4), 9.5, 22.0, -10.0),  # the red balls pierced
    Shot(2.6, (0.0, 0.0, 3.8), 14.0, -5.0, -9.0),  # the flight, wide and from the side
    Shot(5.0, (3.0, 0.0, 3.6), 12.5, -20.0, -9.0),
    Shot(6.6, (5.5, 0.0, 3.3), 10.5, -48.0, -9.0),  # the hits, the board's face at an angle
    Shot(8.6, (6.2, 0.0, 3.2), 9.5, -58.0, -8.0),
)


def camera_at(t: float, width: int, height: int, shots: Sequence[Shot] = DEMO_SHOTS) -> View:
    """The demo's eased camera at time ``t``."""
    return _eased(t, width, height, shots)
