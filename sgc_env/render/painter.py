"""The look of every SGC picture (``env.render()`` and ``sgc demo``): one TinyRenderer pass,
then sky, floor, shadows, trails and nails on top.

TinyRenderer draws the bodies with diffuse and specular light from :data:`SUN`. Everything
else is composited with numpy and OpenCV on the pixels the renderer leaves empty: below the
horizon a checkered floor seen through the camera's homography, with soft shadows of rods,
balls and the target board cast along :data:`SUN` and a haze that grows with depth; above it a
sky graded from the horizon up. Trails are anti-aliased polylines that fade with age, nails
small ringed dots; both are depth-tested against the renderer's depth buffer, so a rod or the
board hides them. TinyRenderer's own shadow pass (``shadow=1``) costs about 2.3 times a plain
frame with a floor body (``scripts/bench_render.py``); these shadows cost a few milliseconds.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import cast

import cv2
import numpy as np

from sgc_env.render.camera import FAR, NEAR, View
from sgc_env.simulator import pybullet

__all__ = ["SUN", "TRAIL_SECONDS", "Caster", "Painter", "Trail", "horizon_row", "linear_depth"]

SUN = np.array([-0.35, 0.45, -1.0]) / np.linalg.norm([-0.35, 0.45, -1.0])
"""Direction the sunlight travels (from upper left, behind the camera's usual side)."""
LIGHT = {"lightAmbientCoeff": 0.55, "lightDiffuseCoeff": 0.55, "lightSpecularCoeff": 0.35}
SKY_HORIZON = np.array([222.0, 232.0, 240.0])
SKY_ZENITH = np.array([96.0, 146.0, 206.0])
FLOOR_LIGHT = np.array([212.0, 214.0, 196.0])
FLOOR_DARK = np.array([178.0, 186.0, 166.0])
CHECK = 2.0
"""Floor tile edge (m) of the demo; the env picks one to suit its scene's size."""
HAZE = 55.0
"""Depth (m) at which the floor has faded 63% of the way to the horizon colour."""
SHADOW = 0.55
"""Share of light left in a full shadow."""
TRAIL_SECONDS = 1.6


@dataclass(frozen=True)
class Trail:
    """Recent tip positions of one rod (oldest first) and their times."""

    points: np.ndarray
    times: np.ndarray


@dataclass(frozen=True)
class Caster:
    """A shadow caster: a segment with a radius (a rod), a point with one (a ball), or a
    box given by its 8 corners (``corners``)."""

    a: np.ndarray | None = None
    b: np.ndarray | None = None
    radius: float = 0.0
    corners: np.ndarray | None = None

    def ground_outline(self) -> np.ndarray:
        """Outline of the shadow on the floor ``z = 0`` (n, 3)."""
        if self.corners is not None:
            flat = _to_floor(self.corners)[:, :2].astype(np.float32)
            hull = cast(np.ndarray, cv2.convexHull(flat))[:, 0, :]
            return np.c_[hull, np.zeros(len(hull))]
        if self.a is None:
            raise ValueError("Caster: give a point (a), a segment (a, b) or corners")
        a = _to_floor(self.a[None])[0]
        b = a if self.b is None else _to_floor(self.b[None])[0]
        ring = np.linspace(0.0, 2.0 * np.pi, 14, endpoint=False)
        circle = self.radius * np.c_[np.cos(ring), np.sin(ring), np.zeros_like(ring)]
        pts = np.r_[a + circle, b + circle][:, :2].astype(np.float32)
        hull = cv2.convexHull(pts)[:, 0, :]
        return np.c_[hull, np.zeros(len(hull))]


def _to_floor(points: np.ndarray) -> np.ndarray:
    """Points moved along the sunlight onto ``z = 0``."""
    p = np.asarray(points, float)
    return p - (p[:, 2:3] / SUN[2]) * SUN


def _floor_texture(check: float) -> tuple[np.ndarray, np.ndarray]:
    """One 2x2-tile period of the checker (tile edge ``check`` m; RGB uint8) and its
    texel->world map."""
    px = 64
    half = px // 2
    tex: np.ndarray = np.empty((px, px, 3), np.uint8)
    tex[:] = FLOOR_LIGHT
    tex[:half, :half] = FLOOR_DARK
    tex[half:, half:] = FLOOR_DARK
    tex = cv2.GaussianBlur(tex, (3, 3), 0)
    scale = 2.0 * check / px
    to_world = np.array([[scale, 0.0, 0.0], [0.0, scale, 0.0], [0.0, 0.0, 1.0]])
    return tex, to_world


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


@dataclass(frozen=True)
class _Scenery:
    """The per-view constants of :meth:`Painter._scenery`."""

    sky: np.ndarray
    top: int
    to_pixel: np.ndarray
    full: np.ndarray
    dark: np.ndarray
    plain: np.ndarray


class Painter:
    """Renders and composites one frame (see the module docstring).

    The floor is not a body: TinyRenderer's cost grows with the pixels it shades, and a floor
    covering half the frame made every frame about four times dearer. The background below the
    (level) horizon is the floor ``z = 0``, computed at half resolution and scaled up.
    """

    def __init__(self, client: int, colors: Sequence[Sequence[float]],
                 nails: Sequence[np.ndarray], check: float = CHECK,
                 haze: float = HAZE) -> None:  # fmt: skip
        self.client = client
        self.haze = haze
        self._cached: tuple[tuple, _Scenery] | None = None
        self.set_scene(colors, nails)
        self._texture, self._tex_to_world = _floor_texture(check)

    def set_scene(self, colors: Sequence[Sequence[float]], nails: Sequence[np.ndarray]) -> None:
        """Per body: its colour (RGBA in 0..1) and its nails (n, 3), drawn as dots."""
        self.colors = [np.array(c[:3], np.float32) * 255.0 for c in colors]
        self.nails = [np.asarray(n, float).reshape(-1, 3) for n in nails]

    def frame(self, view: View, trails: Sequence[Trail], casters: Sequence[Caster],
              now: float) -> np.ndarray:  # fmt: skip
        """One RGB frame (height, width, 3) uint8."""
        w, h = view.width, view.height
        _, _, rgba, depth_buffer, _ = pybullet.getCameraImage(
            w, h, view.view, view.projection, renderer=pybullet.ER_TINY_RENDERER,
            lightDirection=list(-SUN * 100.0), flags=pybullet.ER_NO_SEGMENTATION_MASK,
            physicsClientId=self.client, **LIGHT,
        )  # fmt: skip
        image = np.reshape(rgba, (h, w, 4))[:, :, :3].astype(np.uint8)
        depth = np.reshape(depth_buffer, (h, w))
        empty = depth >= 1.0 - 1e-6
        np.copyto(image, self._background(view, casters), where=empty[..., None])
        for rod, trail in enumerate(trails):
            self._paint_trail(image, view, depth, trail, self.colors[rod], now)
        for rod, nails in enumerate(self.nails):
            self._paint_nails(image, view, depth, nails, self.colors[rod])
        return image

    def _background(self, view: View, casters: Sequence[Caster]) -> np.ndarray:
        """Sky above the horizon, the shaded, hazy checkered floor below it."""
        scenery = self._scenery(view)
        layer = scenery.sky.copy()
        if scenery.top < view.height:
            layer[scenery.top :] = self._floor(view, casters, scenery)
        return layer

    def forget_view(self) -> None:
        """Drop the per-view cache (benchmarks of a camera that moves every frame)."""
        self._cached = None

    def _scenery(self, view: View) -> _Scenery:
        """What does not move while the camera holds still: the sky, the floor's lit and
        hazed checker and how much of it a full shadow takes away (cached per view)."""
        key = (view.view, view.projection, view.width, view.height)
        if self._cached is not None and self._cached[0] == key:
            return self._cached[1]
        w, h = view.width, view.height
        sky = np.empty((h, w, 3), np.uint8)
        horizon = horizon_row(view)
        top = int(np.clip(np.ceil(horizon), 0, h))
        if top > 0:
            rows = np.arange(top, dtype=np.float32)
            up = np.clip((horizon - rows) / (0.9 * h), 0.0, 1.0) ** 0.7
            band = SKY_HORIZON + (SKY_ZENITH - SKY_HORIZON) * up[:, None]
            sky[:top] = band.astype(np.uint8)[:, None, :]
        hw, hh = (w + 1) // 2, (h - top + 1) // 2
        # half-resolution pixels of the rows below ``top``
        to_half = np.array([[0.5, 0.0, 0.0], [0.0, 0.5, -0.5 * top], [0.0, 0.0, 1.0]])
        to_pixel = to_half @ np.array(
            [[w / 2, 0.0, w / 2], [0.0, -h / 2, h / 2], [0.0, 0.0, 1.0]]
        ) @ view.matrix[[0, 1, 3]][:, [0, 1, 3]]  # fmt: skip
        checker = cv2.warpPerspective(
            self._texture, to_pixel @ self._tex_to_world, (hw, hh),
            flags=cv2.INTER_LINEAR, borderMode=cv2.BORDER_WRAP,
        ).astype(np.float32)  # fmt: skip
        # distance of each floor pixel along the view axis, a ratio of affine functions of
        # the pixel: (x, y, 1) ~ to_world @ (px, py, 1), distance = -(view row 2) @ (x, y, 0, 1)
        to_world = np.linalg.inv(to_pixel)
        row = np.asarray(view.view, float).reshape(4, 4).T[2]
        num = -(row[0] * to_world[0] + row[1] * to_world[1] + row[3] * to_world[2])
        gx = np.arange(hw, dtype=np.float32) + 0.5
        gy = (np.arange(hh, dtype=np.float32) + 0.5)[:, None]
        den = to_world[2, 0] * gx + to_world[2, 1] * gy + to_world[2, 2]
        dist = (num[0] * gx + num[1] * gy + num[2]) / den
        haze = np.where(dist > 0.0, -np.expm1(-np.maximum(dist, 0.0) / self.haze), 1.0)
        clear = (1.0 - haze)[..., None].astype(np.float32)
        # lit = checker (1 - (1 - SHADOW) soft) hazed towards the horizon colour:
        # lit = full - dark * soft
        full = checker * clear + SKY_HORIZON.astype(np.float32) * (1.0 - clear)
        dark = checker * clear * np.float32(1.0 - SHADOW)
        scenery = _Scenery(sky, top, to_pixel, full, dark,
                           np.clip(full, 0, 255).astype(np.uint8))  # fmt: skip
        self._cached = (key, scenery)
        return scenery

    def _floor(self, view: View, casters: Sequence[Caster], scenery: _Scenery) -> np.ndarray:
        """Image rows ``top:`` of the floor, computed at half resolution and scaled up; only
        the box around the shadows is recomputed each frame."""
        w, h, top = view.width, view.height, scenery.top
        hh, hw = scenery.full.shape[:2]
        shade: np.ndarray = np.zeros((hh, hw), np.uint8)
        for caster in casters:
            outline, depth = view.project(caster.ground_outline())
            if np.all(depth > 0.0):
                pts = (outline - [0.0, top]) * 0.5
                cv2.fillPoly(shade, [np.round(pts * 16).astype(np.int32)], 255,
                             lineType=cv2.LINE_AA, shift=4)  # fmt: skip
        half = scenery.plain.copy()
        ys, xs = np.nonzero(shade.any(axis=1))[0], np.nonzero(shade.any(axis=0))[0]
        if len(ys):
            y0, y1 = max(int(ys[0]) - 5, 0), min(int(ys[-1]) + 6, hh)
            x0, x1 = max(int(xs[0]) - 5, 0), min(int(xs[-1]) + 6, hw)
            soft = cv2.GaussianBlur(shade[y0:y1, x0:x1], (0, 0), 1.2,
                                    borderType=cv2.BORDER_CONSTANT)  # fmt: skip
            box = np.s_[y0:y1, x0:x1]
            amount = (soft.astype(np.float32) / 255.0)[..., None]
            lit = scenery.full[box] - scenery.dark[box] * amount
            half[box] = np.clip(lit, 0, 255).astype(np.uint8)
        return cv2.resize(half, (w, 2 * hh), interpolation=cv2.INTER_LINEAR)[: h - top]

    def _visible(self, view: View, depth, points) -> tuple[np.ndarray, np.ndarray]:
        """Pixel positions and a mask of points in front of whatever the renderer drew
        (``depth``: the renderer's non-linear depth buffer, linearised at the points only)."""
        px, w = view.project(points)
        ix = np.clip(px[:, 0].astype(int), 0, view.width - 1)
        iy = np.clip(px[:, 1].astype(int), 0, view.height - 1)
        inside = (w > 0.0) & (px[:, 0] >= 0) & (px[:, 0] < view.width)
        inside &= (px[:, 1] >= 0) & (px[:, 1] < view.height)
        return px, inside & (w <= linear_depth(depth[iy, ix]) + 0.08)

    def _paint_trail(self, image, view, depth, trail: Trail, color, now: float) -> None:
        if len(trail.points) < 2:
            return
        px, visible = self._visible(view, depth, trail.points)
        if visible.sum() < 2:
            return
        x0, y0 = np.floor(px[visible].min(axis=0)).astype(int) - 3
        x1, y1 = np.ceil(px[visible].max(axis=0)).astype(int) + 3
        x0, y0 = max(x0, 0), max(y0, 0)
        x1, y1 = min(x1, view.width), min(y1, view.height)
        alpha = np.zeros((y1 - y0, x1 - x0), np.uint8)
        age = np.clip((now - trail.times) / TRAIL_SECONDS, 0.0, 1.0)
        fixed = np.round((px - [x0, y0]) * 16).astype(np.int32)
        for k in range(len(px) - 1):
            if visible[k] and visible[k + 1]:
                level = int(230 * (1.0 - age[k + 1]) ** 1.5)
                if level > 4:
                    cv2.line(alpha, tuple(fixed[k]), tuple(fixed[k + 1]), level, 2,
                             cv2.LINE_AA, shift=4)  # fmt: skip
        a = alpha.astype(np.float32)[..., None] / 255.0
        patch = image[y0:y1, x0:x1].astype(np.float32)
        image[y0:y1, x0:x1] = (patch + (color - patch) * a).astype(np.uint8)

    def _paint_nails(self, image, view, depth, nails, color) -> None:
        px, visible = self._visible(view, depth, nails)
        fill = tuple(float(c) for c in color)
        # 3 px dots with a 1 px ring at the demo's 960 px width, scaled down with the frame
        scale = min(1.0, max(view.width / 960.0, 0.4))
        outer, inner = round(4 * 16 * scale), round(3 * 16 * scale)
        for p in np.round(px[visible] * 16).astype(np.int32):
            centre = (int(p[0]), int(p[1]))
            cv2.circle(image, centre, outer, (40, 40, 40), -1, cv2.LINE_AA, shift=4)
            cv2.circle(image, centre, inner, fill, -1, cv2.LINE_AA, shift=4)
