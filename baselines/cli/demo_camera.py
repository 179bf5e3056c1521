"""The demo's camera: shots keyed by time, eased from one to the next, as the paper's plates
change viewpoint.

A shot says where the camera looks (``look_at``), from how far, and from which side (yaw and
pitch in PyBullet's orbit convention). Between two key times the camera eases (smoothstep) so
that the video never cuts; the plates are taken from whichever shot is on.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from sgc_env.simulator import pybullet

__all__ = ["DEMO_SHOTS", "Shot", "View", "camera_at"]

NEAR, FAR = 0.1, 400.0


@dataclass(frozen=True)
class Shot:
    """Camera at ``time`` s: orbit ``distance`` m around ``look_at``; ``fov`` vertical degrees."""

    time: float
    look_at: tuple[float, float, float]
    distance: float
    yaw: float
    pitch: float
    fov: float = 50.0


DEMO_SHOTS: tuple[Shot, ...] = (
    Shot(0.0, (-7.0, 0.0, 3.0), 9.0, 32.0, -12.0),  # the launch, seen from ahead: board behind
    Shot(1.3, (-5.5, 0.0, 3.4), 9.5, 22.0, -10.0),  # the red balls pierced
    Shot(2.6, (0.0, 0.0, 3.8), 14.0, -5.0, -9.0),  # the flight, wide and from the side
    Shot(5.0, (3.0, 0.0, 3.6), 12.5, -20.0, -9.0),
    Shot(6.6, (5.5, 0.0, 3.3), 10.5, -48.0, -9.0),  # the hits, the board's face at an angle
    Shot(8.6, (6.2, 0.0, 3.2), 9.5, -58.0, -8.0),
)


@dataclass(frozen=True)
class View:
    """One frame's camera: PyBullet view and projection matrices and the image size."""

    view: tuple[float, ...]
    projection: tuple[float, ...]
    width: int
    height: int

    @property
    def matrix(self) -> np.ndarray:
        """``projection @ view`` as a 4x4 array (PyBullet's matrices are column-major)."""
        v = np.asarray(self.view, float).reshape(4, 4).T
        p = np.asarray(self.projection, float).reshape(4, 4).T
        return p @ v

    def project(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Pixel coordinates (n, 2) and camera distance along the view axis (n,) of world
        points (n, 3); points behind the camera get a negative distance."""
        pts = np.asarray(points, float).reshape(-1, 3)
        clip = np.c_[pts, np.ones(len(pts))] @ self.matrix.T
        w = clip[:, 3]
        safe = np.where(np.abs(w) < 1e-9, 1e-9, w)
        px = (clip[:, 0] / safe + 1.0) * 0.5 * self.width
        py = (1.0 - clip[:, 1] / safe) * 0.5 * self.height
        return np.c_[px, py], w

    @property
    def eye(self) -> np.ndarray:
        """Camera position in world."""
        v = np.asarray(self.view, float).reshape(4, 4).T
        return -v[:3, :3].T @ v[:3, 3]


def _ease(u: float) -> float:
    u = min(max(u, 0.0), 1.0)
    return u * u * (3.0 - 2.0 * u)


def camera_at(t: float, width: int, height: int, shots: Sequence[Shot] = DEMO_SHOTS) -> View:
    """The eased camera at time ``t`` (held before the first and after the last shot)."""
    if not shots:
        raise ValueError("camera_at: no shots")
    times = [s.time for s in shots]
    k = int(np.searchsorted(times, t, side="right"))
    a = shots[max(k - 1, 0)]
    b = shots[min(k, len(shots) - 1)]
    u = 0.0 if b.time <= a.time else _ease((t - a.time) / (b.time - a.time))

    def mix(x: float, y: float) -> float:
        return x + (y - x) * u

    look = [mix(x, y) for x, y in zip(a.look_at, b.look_at, strict=True)]
    view = pybullet.computeViewMatrixFromYawPitchRoll(
        look, mix(a.distance, b.distance), mix(a.yaw, b.yaw), mix(a.pitch, b.pitch), 0.0, 2
    )
    projection = pybullet.computeProjectionMatrixFOV(
        mix(a.fov, b.fov), width / height, NEAR, FAR
    )
    return View(tuple(view), tuple(projection), int(width), int(height))


def linear_depth(depth_buffer: np.ndarray) -> np.ndarray:
    """Metric depth along the view axis from PyBullet's non-linear depth buffer."""
    d = np.asarray(depth_buffer, float)
    return FAR * NEAR / (FAR - (FAR - NEAR) * d)


def horizon_row(view: View) -> float:
    """Image row of the horizon (the camera never rolls, so the horizon is level)."""
    v = np.asarray(view.view, float).reshape(4, 4).T
    forward = -v[2, :3]
    flat = np.array([forward[0], forward[1], 0.0])
    flat /= max(float(np.linalg.norm(flat)), 1e-9)
    return float(view.project((view.eye + 1e5 * flat)[None])[0][0, 1])
