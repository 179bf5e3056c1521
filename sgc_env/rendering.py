"""Rendering helpers: a camera description and visual-only nail markers.

``rgb_array`` uses PyBullet's TinyRenderer (CPU, headless). Nails are shown as small
visual-only spheres created once per scenario (no collision shape, so physics is unchanged).
Path traces: ``addUserDebugLine`` exists only in the GUI and TinyRenderer does not draw debug
items, so rgb_array frames show the nails (which sample the path) and no trails.
"""

from __future__ import annotations

import os
import sys
from dataclasses import dataclass, fields
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from sgc_env.scenario import Scenario
    from sgc_env.simulator import Simulator

__all__ = ["CameraConfig", "NailMarkers", "available_render_modes"]


def available_render_modes() -> list[str]:
    """``rgb_array`` always (TinyRenderer); ``human`` only where a GUI can open."""
    headless = sys.platform.startswith("linux") and not os.environ.get("DISPLAY")
    return ["rgb_array"] if headless else ["human", "rgb_array"]


@dataclass(frozen=True)
class CameraConfig:
    """Orbit camera: looks at ``target`` from ``distance`` m at ``yaw``/``pitch`` degrees."""

    distance: float = 3.0
    yaw: float = 45.0
    pitch: float = -25.0
    target: tuple[float, float, float] = (0.5, 0.5, 1.0)
    width: int = 320
    height: int = 240
    fov: float = 60.0

    @classmethod
    def from_dict(cls, options: dict[str, Any] | None) -> CameraConfig:
        if not options:
            return cls()
        known = {f.name for f in fields(cls)}
        unknown = sorted(set(options) - known)
        if unknown:
            raise ValueError(
                f"camera: unknown option(s) {unknown}; expected some of {sorted(known)}"
            )
        values: dict[str, Any] = {k: (tuple(v) if k == "target" else v) for k, v in options.items()}
        cfg = cls(**values)
        if not (int(cfg.width) > 0 and int(cfg.height) > 0):
            raise ValueError(
                f"camera: width and height must be positive, got {cfg.width}x{cfg.height}"
            )
        return cfg

    @property
    def shape(self) -> tuple[int, int, int]:
        return (int(self.height), int(self.width), 3)

    def image(self, sim: Simulator) -> np.ndarray:
        """An (height, width, 3) uint8 frame."""
        return sim.orbit_image(
            int(self.width), int(self.height), self.target, self.distance, self.yaw, self.pitch,
            self.fov,
        )  # fmt: skip

    def point_gui(self, sim: Simulator) -> None:
        sim.point_gui_camera(self.target, self.distance, self.yaw, self.pitch)


class NailMarkers:
    """A pool of marker spheres reused across scenarios; unused ones are parked far away."""

    RADIUS = 0.02

    def __init__(self, sim: Simulator) -> None:
        self.sim = sim
        self.uids: list[int] = []

    def clear(self) -> None:
        for uid in self.uids:
            self.sim.move(uid, (0.0, 0.0, -1e3))

    def place(self, scenario: Scenario) -> None:
        nails = [(g.nail, b.color) for b in scenario.bodies for g in b.goals if g.nail is not None]
        while len(self.uids) < len(nails):
            self.uids.append(self.sim.add_marker(self.RADIUS, (1.0, 0.8, 0.1, 0.9)))
        self.clear()
        for uid, (nail, _) in zip(self.uids, nails, strict=False):
            self.sim.move(uid, nail)
