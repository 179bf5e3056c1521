"""Point-to-path goals: named curves sampled into point-to-nail goals timed by routing."""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from sgc_env.scenario.model import Goal, ScenarioError, Vec3

__all__ = ["parametric_curve", "path_goals"]

# ---------------------------------------------------------------- point-to-path goals


def parametric_curve(kind: str, **params: Any) -> Callable[[float], np.ndarray]:
    """A named path function s in [0, 1] -> point: ``line``, ``arc``, ``helix`` or ``polyline``."""
    if kind == "line":
        a, b = np.asarray(params["start"], float), np.asarray(params["end"], float)
        return lambda s: a + (b - a) * s
    if kind in ("arc", "helix"):
        c = np.asarray(params["center"], float)
        r = float(params["radius"])
        if kind == "arc":
            a0, a1 = float(params["start_angle"]), float(params["end_angle"])
            height = float(params.get("height", 0.0))
        else:
            a0 = float(params.get("start_angle", 0.0))
            a1 = a0 + 2 * math.pi * float(params["turns"])
            height = float(params["height"])
        return lambda s: (
            c
            + np.array(
                [r * math.cos(a0 + (a1 - a0) * s), r * math.sin(a0 + (a1 - a0) * s), height * s]
            )
        )
    if kind == "polyline":
        pts = np.asarray(params["waypoints"], float)
        seg = np.linalg.norm(np.diff(pts, axis=0), axis=1)
        cum = np.concatenate(([0.0], np.cumsum(seg))) / max(seg.sum(), 1e-300)
        return lambda s: np.array([np.interp(s, cum, pts[:, j]) for j in range(3)])
    raise ScenarioError(f"unknown curve {kind!r}; expected one of line, arc, helix, polyline")


def path_goals(
    path: Callable[[float], Sequence[float] | np.ndarray],
    samples: int,
    *,
    time: float | None = None,
    point: Vec3 = (0.0, 0.0, 0.0),
    weight: float = 1.0,
    arc_resolution: int = 64,
) -> tuple[Goal, ...]:
    """Sample a point-to-path constraint into ``samples`` point-to-nail goals at s = k/samples.

    Routing weights are chord/arc-length of each sample interval, so with equal base weights
    the routed times are proportional to arc length along the path. Only the last sample
    carries ``time`` (time-critical); the others are timed by routing.
    """
    if samples < 1:
        raise ScenarioError(f"path samples: expected an integer >= 1, got {samples}")
    goals = []
    for k in range(1, samples + 1):
        s0, s1 = (k - 1) / samples, k / samples
        fine = np.asarray(
            [path(s0 + (s1 - s0) * j / arc_resolution) for j in range(arc_resolution + 1)]
        )
        arc = float(np.linalg.norm(np.diff(fine, axis=0), axis=1).sum())
        chord = float(np.linalg.norm(fine[-1] - fine[0]))
        w = weight * (chord / arc if arc > 0 else 1.0)
        last = k == samples
        goals.append(
            Goal(
                nail=tuple(float(x) for x in fine[-1]),  # type: ignore[arg-type]
                point=point,
                time=time if last else None,
                critical=(time is not None) if last else False,
                weight=w,
            )
        )
    return tuple(goals)
