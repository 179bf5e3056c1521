"""What ``env.render()`` draws: the painter's look on a :class:`RenderWorld` of the env's scene,
seen by a camera that frames the whole scene (``"fixed"``) or follows its bodies
(``"tracking"``).

The fixed camera is computed from the scene's extent (:func:`scene_points`: every body's start,
every nail, every prop along its path until the episode ends), once per scenario, so a random
env's camera changes with each drawn scene and never in the middle of an episode. Trails are
the tracked points at the frames rendered (``RecordVideo`` renders every step); they restart
when time goes back (a reset).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, fields
from typing import TYPE_CHECKING, Any

import numpy as np

from sgc_env.render.camera import View, frame_points, orbit_view
from sgc_env.render.painter import TRAIL_SECONDS, Painter, Trail
from sgc_env.render.world import RenderWorld

if TYPE_CHECKING:
    from sgc_env.scenario import Scenario

__all__ = ["CameraSpec", "SceneRenderer", "check_size", "scene_points"]

MODES = ("fixed", "tracking")
ROD_SCALE = 0.007
"""Drawn rod radius as a share of the scene's diagonal (never below the physical radius)."""
HAZE_SCALE = 2.75
"""Floor haze depth as a multiple of the scene's diagonal (the demo's 55 m on its 20 m scene):
far tiles fade into the horizon instead of aliasing."""
MAX_SIZE = 4096


def check_size(name: str, value: object) -> int:
    """A frame side in pixels, or a ValueError naming ``name``."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise ValueError(f"{name}: expected an integer number of pixels, got {value!r}")
    if not 16 <= int(value) <= MAX_SIZE:
        raise ValueError(f"{name}: expected 16 to {MAX_SIZE} pixels, got {value}")
    return int(value)


@dataclass(frozen=True)
class CameraSpec:
    """The ``camera`` argument: ``"fixed"`` (default) frames the whole scene, ``"tracking"``
    follows the bodies; a dict may set ``mode``, ``yaw``, ``pitch``, ``fov`` (degrees), or
    ``target`` and ``distance`` for a camera that never moves."""

    mode: str = "fixed"
    yaw: float = -40.0
    pitch: float = -22.0
    fov: float = 50.0
    target: tuple[float, float, float] | None = None
    distance: float | None = None

    @classmethod
    def parse(cls, camera: str | dict[str, Any] | None) -> CameraSpec:
        if camera is None:
            return cls()
        options: dict[str, Any] = {"mode": camera} if isinstance(camera, str) else dict(camera)
        known = {f.name for f in fields(cls)}
        unknown = sorted(set(options) - known)
        if unknown:
            sized = {"width", "height"} & set(unknown)
            hint = " (the frame size is width=, height=)" if sized else ""
            raise ValueError(
                f"camera: unknown option(s) {unknown}; expected some of {sorted(known)}{hint}"
            )
        if options.get("mode", "fixed") not in MODES:
            raise ValueError(f"camera: mode must be one of {MODES}, got {options['mode']!r}")
        if "target" in options:
            target = np.asarray(options["target"], float)
            if target.shape != (3,) or not np.all(np.isfinite(target)):
                raise ValueError(
                    f"camera: target must be 3 finite numbers, got {options['target']!r}"
                )
            options["target"] = tuple(float(x) for x in target)
        if ("target" in options) != ("distance" in options):
            raise ValueError("camera: give target and distance together")
        spec = cls(**options)
        if not 1.0 <= float(spec.fov) <= 170.0:
            raise ValueError(f"camera: fov must be 1 to 170 degrees, got {spec.fov}")
        if spec.distance is not None and not float(spec.distance) > 0.0:
            raise ValueError(f"camera: distance must be positive, got {spec.distance}")
        return spec


def scene_points(scenario: Scenario, end_time: float, samples: int = 64) -> np.ndarray:
    """Points (n, 3) the fixed camera must show: the bodies' starts, the nails and the props'
    paths, each widened by its body's or prop's reach along the axes.

    A prop that goals are nailed to (a ball to pierce, a fish to meet) counts until the last
    of those goals, after which it may leave (the paper's balls fly on); others count over
    the whole episode (``end_time``)."""
    clouds: list[tuple[np.ndarray, float]] = []
    for b in scenario.bodies:
        nails = [g.nail for g in b.goals if g.nail is not None]
        clouds.append((np.asarray([b.position, *nails], float), _reach(b.shape, b.size)))
    for p in scenario.props:
        met = [float(g.time) for b in scenario.bodies for g in b.goals
               if g.nail_prop == p.name and g.time is not None]  # fmt: skip
        until = max(met) if met else end_time
        path = [p.position_at(float(t)) for t in np.linspace(0.0, max(until, 0.0), samples)]
        clouds.append((np.asarray(path, float), _reach(p.shape, p.size)))
    axes = np.r_[np.zeros((1, 3)), np.eye(3), -np.eye(3)]
    return np.concatenate([(pts[:, None, :] + reach * axes).reshape(-1, 3)
                           for pts, reach in clouds])  # fmt: skip


def _reach(shape: str, size: Sequence[float]) -> float:
    """How far a body or prop reaches from its centre."""
    if shape == "rod":
        return float(size[0]) / 2.0
    if shape == "box":
        return float(np.linalg.norm(size))
    return float(size[0])


def _tile(diagonal: float) -> float:
    """A round floor tile edge (1, 2 or 5 times a power of ten) near a sixth of the scene."""
    want = diagonal / 6.0
    power = 10.0 ** math.floor(math.log10(want))
    return min((k * power for k in (1.0, 2.0, 5.0, 10.0)), key=lambda x: abs(x - want))


class SceneRenderer:
    """Frames of one env (see the module docstring)."""

    def __init__(self, width: int, height: int, camera: CameraSpec) -> None:
        self.width, self.height, self.camera = width, height, camera
        self._scenario: Scenario | None = None
        self._geometry: tuple = ()
        self._world: RenderWorld | None = None
        self._painter: Painter | None = None
        self._fixed: View | None = None
        self._diagonal = 1.0
        self._points: list[np.ndarray] = []
        self._times: list[float] = []

    def _prepare(self, scenario: Scenario, end_time: float) -> None:
        geometry = (
            tuple((b.shape, b.size, b.color) for b in scenario.bodies),
            tuple((p.name, p.shape, p.size, p.color, p.position) for p in scenario.props),
        )
        points = scene_points(scenario, end_time)
        self._diagonal = max(float(np.linalg.norm(np.ptp(points, axis=0))), 0.5)
        nails = [np.array([g.nail for g in b.goals if g.nail is not None], float).reshape(-1, 3)
                 for b in scenario.bodies]  # fmt: skip
        colors = [b.color for b in scenario.bodies]
        if geometry != self._geometry or self._world is None:
            self.close()
            self._world = RenderWorld(scenario, ROD_SCALE * self._diagonal)
            self._painter = Painter(self._world.client, colors, nails, _tile(self._diagonal),
                                   HAZE_SCALE * self._diagonal)
            self._geometry = geometry
        else:
            assert self._painter is not None
            self._painter.set_scene(colors, nails)
        spec = self.camera
        if spec.target is not None and spec.distance is not None:
            self._fixed = orbit_view(spec.target, spec.distance, spec.yaw, spec.pitch, spec.fov,
                                     self.width, self.height)  # fmt: skip
        else:
            self._fixed = frame_points(points, self.width, self.height, yaw=spec.yaw,
                                       pitch=spec.pitch, fov=spec.fov)  # fmt: skip
        self._scenario = scenario
        self._points, self._times = [], []

    def view(
        self, scenario: Scenario, end_time: float, positions: Sequence[Sequence[float]]
    ) -> View:
        """The camera for a frame with the bodies at ``positions``."""
        if scenario is not self._scenario:
            self._prepare(scenario, end_time)
        assert self._fixed is not None
        spec = self.camera
        if spec.mode == "fixed" or spec.target is not None:
            return self._fixed
        bodies = np.asarray(positions, float).reshape(-1, 3)
        around = 0.25 * self._diagonal * np.r_[np.eye(3), -np.eye(3)]
        return frame_points((bodies[:, None, :] + around).reshape(-1, 3), self.width,
                            self.height, yaw=spec.yaw, pitch=spec.pitch, fov=spec.fov)  # fmt: skip

    def frame(self, view: View, now: float, positions: Sequence[Sequence[float]],
              orientations: Sequence[Sequence[float]], points: Sequence[Sequence[float]],
              prop_positions: Sequence[Sequence[float]]) -> np.ndarray:  # fmt: skip
        """An RGB frame (height, width, 3) uint8 of the scene at time ``now`` seen through
        ``view`` (from :meth:`view`, which prepares the scenario)."""
        assert self._world is not None and self._painter is not None
        if self._times and now < self._times[-1]:
            self._points, self._times = [], []
        self._points.append(np.asarray(points, float).reshape(-1, 3))
        self._times.append(float(now))
        first = int(np.searchsorted(self._times, now - TRAIL_SECONDS))
        del self._points[:first], self._times[:first]
        recent, stamps = np.stack(self._points), np.asarray(self._times)
        trails = [Trail(recent[:, b], stamps) for b in range(recent.shape[1])]
        casters = self._world.update(positions, orientations, prop_positions)
        return self._painter.frame(view, trails, casters, now)

    def close(self) -> None:
        if self._world is not None:
            self._world.close()
            self._world = None
            self._painter = None
