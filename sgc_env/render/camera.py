"""Cameras: PyBullet view and projection matrices with numpy projection, eased shots, and a
camera that frames a box of the world.

A :class:`View` is what one frame is seen through; it projects world points to pixels so that
the painter (and tests) can place trails, nails and shadows and check what is in frame.
:func:`camera_at` eases between :class:`Shot` s (the demo's plates); :func:`frame_points` fits
an orbit camera around a cloud of points (the env's fixed camera and its tracking camera).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from sgc_env.simulator import pybullet

__all__ = ["NEAR", "FAR", "Shot", "View", "camera_at", "frame_points", "orbit_view"]

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


@dataclass(frozen=True)
class View:
    """One frame's camera: PyBullet view and projection matrices and the image size, plus the
    orbit it was made from (for the GUI camera of ``render_mode="human"``)."""

    view: tuple[float, ...]
    projection: tuple[float, ...]
    width: int
    height: int
    orbit: tuple[tuple[float, float, float], float, float, float] | None = None
    """(look_at, distance, yaw, pitch) where known."""

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


def orbit_view(look_at: Sequence[float], distance: float, yaw: float, pitch: float, fov: float,
               width: int, height: int) -> View:  # fmt: skip
    """PyBullet's orbit camera (degrees, z up, no roll) as a :class:`View`."""
    look = tuple(float(x) for x in look_at)
    view = pybullet.computeViewMatrixFromYawPitchRoll(look, distance, yaw, pitch, 0.0, 2)
    projection = pybullet.computeProjectionMatrixFOV(fov, width / height, NEAR, FAR)
    return View(tuple(view), tuple(projection), int(width), int(height),
                (look, float(distance), float(yaw), float(pitch)))  # type: ignore[arg-type]  # fmt: skip


def _ease(u: float) -> float:
    u = min(max(u, 0.0), 1.0)
    return u * u * (3.0 - 2.0 * u)


def camera_at(t: float, width: int, height: int, shots: Sequence[Shot]) -> View:
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
    return orbit_view(look, mix(a.distance, b.distance), mix(a.yaw, b.yaw), mix(a.pitch, b.pitch),
                      mix(a.fov, b.fov), width, height)  # fmt: skip


def _axes(yaw: float, pitch: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Right, up and forward unit vectors of PyBullet's orbit camera (z up)."""
    view = np.asarray(pybullet.computeViewMatrixFromYawPitchRoll(
        [0.0, 0.0, 0.0], 1.0, yaw, pitch, 0.0, 2), float).reshape(4, 4).T  # fmt: skip
    return view[0, :3], view[1, :3], -view[2, :3]


def frame_points(points: np.ndarray, width: int, height: int, *, yaw: float = -40.0,
                 pitch: float = -22.0, fov: float = 50.0, fill: float = 0.8) -> View:  # fmt: skip
    """An orbit camera from ``yaw``/``pitch``, looking at the middle of ``points`` (n, 3), that
    shows them all inside the central ``fill`` of the frame's width and height.

    For a point at offset ``c`` from the look-at point, with camera axes (r, u, f), it lies
    inside when ``|c.r| <= k_x (d + c.f)`` and ``|c.u| <= k_y (d + c.f)`` (``k`` the half
    field of view's tangent times ``fill``): the distance ``d`` is the largest such bound.
    """
    pts = np.asarray(points, float).reshape(-1, 3)
    centre = (pts.min(axis=0) + pts.max(axis=0)) / 2.0
    offsets = pts - centre
    right, up, forward = _axes(yaw, pitch)
    ky = math.tan(math.radians(fov) / 2.0) * fill
    kx = ky * width / height
    along = offsets @ forward
    need = np.maximum(np.abs(offsets @ right) / kx, np.abs(offsets @ up) / ky) - along
    distance = max(float(need.max()), float((2.0 * NEAR - along).max()), 1e-3)
    return orbit_view(centre, distance, yaw, pitch, fov, width, height)
