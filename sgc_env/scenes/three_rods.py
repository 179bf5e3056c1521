"""The paper's demo scene (Liu, Ko & Chang 1993, Plates 1-8), built from path functions.

Three rods fly along designated paths, sampled into 25, 16 and 17 point-to-nail goals for
their tips; near the start each tip pierces a red ball that moves kinematically; at the end
each tip hits a target board at its own time and embeds itself in it. Orientation goals keep
every rod pointing along its path's tangent; the teal rod turns one somersault on the way.

``build_three_rods()`` returns the scenario as plain YAML-ready data;
``python -m sgc_env.scenes`` rewrites ``sgc_env/scenario/builtin/three_rods.yaml``
from it (a test checks that the shipped file is what this module builds).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from sgc_env.paper import quaternion as quat
from sgc_env.scenario.load import builtin_path

__all__ = [
    "ROD_SPECS", "RodPath", "RodSpec", "ball_name", "build_three_rods", "rod_entries", "rod_path",
    "write_three_rods_yaml",
]  # fmt: skip

ROD_LENGTH = 1.0
ROD_RADIUS = 0.04
ROD_MASS = 1.0
TIP = (0.0, 0.0, ROD_LENGTH / 2)
BALL_RADIUS = 0.22
BALL_COLOR = (0.85, 0.08, 0.08, 1.0)
PIERCE_TIME = 1.2
EMBED_DEPTH = 0.2
EMBED_DURATION = 0.15
TARGET_FACE_X = 7.9
TARGET_CENTER = (8.0, 0.0, 3.2)
TARGET_HALF_EXTENTS = (0.1, 3.0, 2.2)
LAUNCH_SPEED = 2.5
"""The rods are thrown: they start along their path's tangent at this speed (m/s)."""
FORCE_LIMIT = 150.0
TORQUE_LIMIT = 30.0
MARGIN = 0.5
"""Seconds the episode runs on after the last embed."""


@dataclass(frozen=True)
class RodSpec:
    """One rod: its tip's designated path, how it is sampled, and its red ball and target hit.

    ``waypoints[ball_index]`` is where the tip pierces the ball at ``pierce_time``; the last
    waypoint is on the target face, hit at ``hit_time``. The tip path is the cubic spline
    through the waypoints; ``samples_before`` goals lie on the path up to the ball (the ball
    included), ``samples_after`` from there to the target (the hit included), and one more goal
    embeds the tip ``EMBED_DEPTH`` into the board, where the rod comes to rest.
    """

    name: str
    color: tuple[float, float, float, float]
    waypoints: tuple[tuple[float, float, float], ...]
    ball_index: int
    samples_before: int
    samples_after: int
    hit_time: float
    ball_velocity: tuple[float, float, float]
    somersault_sample: int | None = None
    somersault_weight: float = 0.3
    """Routing weight of the somersault's course: the rod slows down to turn over."""
    pierce_time: float = PIERCE_TIME

    @property
    def goal_count(self) -> int:
        return self.samples_before + self.samples_after + 1


ROD_SPECS: tuple[RodSpec, ...] = (
    RodSpec(
        name="rod_gold",
        color=(0.95, 0.72, 0.15, 1.0),
        waypoints=(
            (-8.8, -3.0, 2.6), (-6.0, -2.6, 3.2), (-3.2, -3.6, 5.2), (-0.8, -5.0, 4.2),
            (0.4, -3.6, 2.2), (-0.4, -2.0, 3.4), (2.6, -2.2, 5.4), (5.4, -1.6, 4.4),
            (TARGET_FACE_X, -1.2, 3.6),
        ),
        ball_index=1,
        samples_before=3,
        samples_after=21,
        hit_time=7.0,
        ball_velocity=(0.0, 0.0, 0.8),
    ),
    RodSpec(
        name="rod_teal",
        color=(0.1, 0.7, 0.7, 1.0),
        waypoints=(
            (-8.8, 0.0, 4.0), (-6.2, 0.2, 4.6), (-2.2, 0.6, 6.0), (1.8, 0.0, 5.6),
            (5.0, 0.4, 3.8), (TARGET_FACE_X, 0.3, 2.8),
        ),
        ball_index=1,
        samples_before=3,
        samples_after=12,
        hit_time=7.5,
        ball_velocity=(0.0, 1.0, 0.0),
        somersault_sample=9,
    ),
    RodSpec(
        name="rod_violet",
        color=(0.55, 0.3, 0.85, 1.0),
        waypoints=(
            (-8.8, 3.0, 1.8), (-6.0, 2.6, 2.4), (-2.0, 5.0, 2.0), (2.0, 4.6, 4.0),
            (5.0, 2.4, 4.4), (TARGET_FACE_X, 1.3, 3.2),
        ),
        ball_index=1,
        samples_before=3,
        samples_after=13,
        hit_time=8.0,
        ball_velocity=(-1.0, 0.0, 0.0),
    ),
)


def _spline(points: np.ndarray):
    """Cubic spline through ``points`` parametrised by cumulative chord length (the knots in
    plain floats: the same sums as numpy's norm and cumsum, without a call per waypoint set)."""
    rows = points.tolist()
    knots, total = [0.0], 0.0
    for (ax, ay, az), (bx, by, bz) in zip(rows[:-1], rows[1:], strict=True):
        dx, dy, dz = bx - ax, by - ay, bz - az
        total += math.sqrt(dx * dx + dy * dy + dz * dz)
        knots.append(total)
    from scipy.interpolate import make_interp_spline

    # check_finite off: the waypoints are finite by construction (it only skips a check);
    # the not-a-knot knot vector scipy would build (cubic: the ends four times, the inner
    # sites but the second and the second last), given so that it is not built by np.r_.
    knot_array = np.array(knots)
    t = np.array([knots[0]] * 4 + knots[2:-2] + [knots[-1]] * 4)
    return make_interp_spline(knot_array, points, k=3, t=t, check_finite=False), knot_array


def _arc_length_samples(
    spline, bounds: tuple[float, ...], counts: tuple[int, ...], fine: int
) -> np.ndarray:
    """Parameters of ``counts[i]`` points equally spaced in arc length on each
    ``(bounds[i], bounds[i + 1]]``, its end included, the arc length measured on ``fine``
    points per stretch (one spline evaluation and one arc-length sum for all stretches)."""
    # np.linspace's arithmetic (i * step + start, the end exact) for all stretches at once,
    # and numpy's norm as its sum of squares: the same floats at a third of the calls' cost.
    starts, stops = np.array(bounds[:-1]), np.array(bounds[1:])
    grids = np.arange(fine, dtype=float) * ((stops - starts) / (fine - 1))[:, None]
    grids += starts[:, None]
    grids[:, -1] = stops
    points = spline(grids.ravel()).reshape(len(grids), fine, -1)
    steps = np.diff(points, axis=1)
    steps *= steps
    arcs = np.zeros(grids.shape)
    lengths = np.sqrt(steps[..., 0] + steps[..., 1] + steps[..., 2])
    np.cumsum(lengths, axis=1, out=arcs[:, 1:])
    out = []
    for grid, arc, count in zip(grids, arcs, counts, strict=True):
        params = np.interp(arc[-1] * np.arange(1, count + 1) / count, arc, grid)
        params[-1] = grid[-1]
        out.append(params)
    return np.concatenate(out)


def _align(previous: quat.Quat, tangent: Sequence[float] | np.ndarray) -> quat.Quat:
    """``previous`` turned by the smallest rotation that points its z axis along ``tangent``.

    Plain-float quaternions (``sgc_env.paper.quaternion``): a random three-rod draw aligns
    ~20 goals per rod, and scipy's ``Rotation`` cost ~30 ms of it."""
    ax, ay, az = quat.rotate(previous, (0.0, 0.0, 1.0))
    tx, ty, tz = map(float, tangent)
    n = math.sqrt(tx * tx + ty * ty + tz * tz)
    tx, ty, tz = tx / n, ty / n, tz / n
    cx, cy, cz = ay * tz - az * ty, az * tx - ax * tz, ax * ty - ay * tx
    sine = math.sqrt(cx * cx + cy * cy + cz * cz)
    angle = math.atan2(sine, ax * tx + ay * ty + az * tz)
    if angle < 1e-12:
        return previous
    turn = quat.exp_normalized((cx / sine * angle, cy / sine * angle, cz / sine * angle))
    qx, qy, qz, qw = quat.mul(turn, previous)
    norm = math.sqrt(qx * qx + qy * qy + qz * qz + qw * qw)
    return (qx / norm, qy / norm, qz / norm, qw / norm)


def _quat(q: quat.Quat) -> list[float]:
    return [round(float(c), 12) for c in q]


def _vec(v: np.ndarray) -> list[float]:
    return [round(float(c), 12) for c in v]


_X_ALONG_PATH = _align((0.0, 0.0, 0.0, 1.0), (1.0, 0.0, 0.0))
"""The rod's axis turned onto world x: every path's start orientation turns it from there."""


@dataclass(frozen=True)
class RodPath:
    """One rod's start state, goals and ball, unrounded: what :func:`rod_entries` writes as
    YAML-ready data and the random family turns into model objects directly.

    ``nails[j]`` and ``orientations[j]`` per goal (the embed last); the pierce goal's nail is
    the ball (``nails`` holds the path's point there); the somersault goal asks for
    ``turn`` (a relative rotation) instead of its orientation."""

    spec: RodSpec
    start: quat.Quat
    com_start: np.ndarray
    launch: np.ndarray
    nails: np.ndarray
    orientations: list[quat.Quat]
    turn: np.ndarray | None
    ball_position: np.ndarray

    @property
    def pierce(self) -> int:
        return self.spec.samples_before - 1


def rod_path(spec: RodSpec, fine: int = 2001) -> RodPath:
    """The rod's path sampled into goals (``fine``: points per arc-length measurement)."""
    points = np.asarray(spec.waypoints, dtype=float)
    spline, knots = _spline(points)

    def tangent(s: np.ndarray) -> np.ndarray:
        return spline(s, nu=1)  # no derivative spline built: a tenth of the rod's build

    ball = spec.ball_index
    params = _arc_length_samples(
        spline, (knots[0], knots[ball], knots[-1]), (spec.samples_before, spec.samples_after), fine
    )
    # One spline evaluation for every goal and one for every tangent, the start's included
    # (the same floats as one call per point); the last parameter is the path's end, where the
    # tip hits the board.
    nails, tangent_rows = spline(params), tangent(np.concatenate(([knots[0]], params)))
    first, tangent_rows = tangent_rows[0], tangent_rows[1:]
    start = _align(_X_ALONG_PATH, first)
    com_start = points[0] - np.asarray(quat.rotate(start, TIP))
    launch = first / np.linalg.norm(first) * LAUNCH_SPEED
    tangents = tangent_rows.tolist()
    orientations, turn = [], None
    previous = start
    for j, direction in enumerate(tangents):
        orientation = _align(previous, direction)
        if j == spec.somersault_sample:
            step = np.asarray(quat.log(quat.mul_conjugate(orientation, previous)))
            angle = float(np.linalg.norm(step))
            axis = step / angle if angle > 1e-9 else np.cross(direction, [0.0, 0.0, 1.0])
            turn = step + 2.0 * math.pi * axis / np.linalg.norm(axis)
        orientations.append(orientation)
        previous = orientation
    end = tangent_rows[-1] / np.linalg.norm(tangent_rows[-1])
    embed = nails[-1] + end * (EMBED_DEPTH / end[0])
    orientations.append(previous)
    ball_position = points[ball] - np.asarray(spec.ball_velocity) * spec.pierce_time
    return RodPath(
        spec, start, com_start, launch, np.vstack((nails, embed)), orientations, turn,
        ball_position,
    )  # fmt: skip


def ball_name(spec: RodSpec) -> str:
    return f"ball_{spec.name[4:]}"


def rod_entries(spec: RodSpec) -> tuple[dict[str, Any], dict[str, Any]]:
    """The rod's body entry (with goals) and its red ball's prop entry."""
    path = rod_path(spec)
    goals: list[dict[str, Any]] = []
    last = len(path.orientations) - 2  # the hit (the embed follows)
    for j, orientation in enumerate(path.orientations[:-1]):
        goal: dict[str, Any] = {"point": list(TIP)}
        if j == path.pierce:
            goal["nail"] = {"prop": ball_name(spec)}
            goal["time"] = spec.pierce_time
        else:
            goal["nail"] = _vec(path.nails[j])
        if j == last:
            goal["time"] = spec.hit_time
        if j == spec.somersault_sample and path.turn is not None:
            goal["relative_rotation"] = _vec(path.turn)
            goal["weight"] = spec.somersault_weight
        else:
            goal["orientation"] = _quat(orientation)
        goals.append(goal)
    goals.append(
        {
            "point": list(TIP),
            "nail": _vec(path.nails[-1]),
            "orientation": _quat(path.orientations[-1]),
            "time": round(spec.hit_time + EMBED_DURATION, 12),
        }
    )
    body = {
        "name": spec.name,
        "shape": "rod",
        "size": [ROD_LENGTH, ROD_RADIUS],
        "mass": ROD_MASS,
        "color": list(spec.color),
        "position": _vec(path.com_start),
        "orientation": _quat(path.start),
        "linear_velocity": _vec(path.launch),
        "force_limit": FORCE_LIMIT,
        "torque_limit": TORQUE_LIMIT,
        "end_velocity": [0.0, 0.0, 0.0],
        "end_angular_velocity": [0.0, 0.0, 0.0],
        "collisions": False,
        "goals": goals,
    }
    ball = {
        "name": ball_name(spec),
        "shape": "sphere",
        "size": [BALL_RADIUS],
        "color": list(BALL_COLOR),
        "position": _vec(path.ball_position),
        "velocity": _vec(np.asarray(spec.ball_velocity)),
        "collisions": False,
    }
    return body, ball


def build_three_rods(
    specs: tuple[RodSpec, ...] = ROD_SPECS, name: str = "three_rods"
) -> dict[str, Any]:
    """The three-rod scenario as YAML-ready data (the paper's rods, or drawn ``specs``)."""
    bodies, props = [], []
    for spec in specs:
        body, ball = rod_entries(spec)
        bodies.append(body)
        props.append(ball)
    props.append(
        {
            "name": "target",
            "shape": "box",
            "size": list(TARGET_HALF_EXTENTS),
            "color": [0.93, 0.93, 0.9, 1.0],
            "position": list(TARGET_CENTER),
            "collisions": False,
        }
    )
    return {
        "name": name,
        "control_frequency": 60,
        "margin": MARGIN,
        "workspace": {"low": [-12.0, -10.0, -1.0], "high": [12.0, 10.0, 12.0]},
        "bodies": bodies,
        "props": props,
    }


def write_three_rods_yaml(path: Path | None = None) -> Path:
    """Write the scene (by default over the shipped built-in) and return where."""
    path = Path(str(builtin_path("three_rods"))) if path is None else path
    header = (
        "# The paper's three-rod demo (Plates 1-8). Generated by `python -m sgc_env.scenes`\n"
        "# from the path functions in sgc_env/scenes/three_rods.py: edit those, not this file.\n"
    )
    path.write_text(header + yaml.safe_dump(build_three_rods(), sort_keys=False, width=100))
    return path
