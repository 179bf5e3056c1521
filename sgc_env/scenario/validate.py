"""Semantic checks of a whole scenario: ranges, names, shapes, the workspace, goal structure."""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from sgc_env.paper.end_rules import END_RULES
from sgc_env.scenario.fields import (
    LIMITS,
    MAX_GOALS,
    MAX_WAYPOINTS,
    SHAPES,
    TIME_GRID_MODES,
    WORKSPACE_LIMIT,
    coords_in_range,
    fail,
    in_range,
    limit_text,
    norm_in_range,
    number,
    quaternion,
    show,
    vector,
)
from sgc_env.scenario.model import Goal, Scenario, Vec3

__all__ = ["check_inside", "validate_structure"]

# ---------------------------------------------------------------- semantic validation


_VELOCITY_LIMITS = (
    ("linear_velocity", "speed"), ("angular_velocity", "spin"),
    ("end_velocity", "speed"), ("end_angular_velocity", "spin"),
)  # fmt: skip


def validate_structure(s: Scenario) -> None:
    if not s.bodies:
        raise fail("bodies", "expected at least one body")
    if s.time_grid not in TIME_GRID_MODES:
        raise fail("time_grid", f"expected one of {TIME_GRID_MODES}, got {show(s.time_grid)}")
    if s.end_velocity_rule not in END_RULES:
        raise fail(
            "end_velocity_rule", f"expected one of {END_RULES}, got {show(s.end_velocity_rule)}"
        )
    if not (isinstance(s.control_frequency, int) and s.control_frequency > 0):
        raise fail(
            "control_frequency", f"expected a positive integer, got {show(s.control_frequency)}"
        )
    in_range(s.control_frequency, "control_frequency", "control_frequency")
    norm_in_range(vector(s.gravity, 3, "gravity"), "gravity", "gravity")
    lo, hi = (
        vector(s.workspace[0], 3, "workspace.low"),
        vector(s.workspace[1], 3, "workspace.high"),
    )
    if any(a >= b for a, b in zip(lo, hi, strict=True)):
        raise fail("workspace", f"low {lo} must be below high {hi} in every axis")
    if max(map(abs, lo + hi)) > WORKSPACE_LIMIT:
        raise fail("workspace", f"must lie inside +-{WORKSPACE_LIMIT:g} m, got {lo} .. {hi}")
    in_range(number(s.margin, "margin", nonneg=True), "margin", "margin")
    if not isinstance(s.allow_saturation, bool):
        raise fail("allow_saturation", f"expected true or false, got {show(s.allow_saturation)}")
    names: set[str] = set()
    prop_names = {p.name for p in s.props}
    for i, b in enumerate(s.bodies):
        p = f"bodies[{i}]"
        if b.name in names or b.name in prop_names:
            raise fail(f"{p}.name", f"duplicate name {show(b.name)}")
        names.add(b.name)
        _validate_shape(b.shape, b.size, p)
        _validate_color(b.color, f"{p}.color")
        for key in ("mass", "force_limit", "torque_limit"):
            in_range(number(getattr(b, key), f"{p}.{key}", positive=True), key, f"{p}.{key}")
        weight = b.mass * float(np.linalg.norm(s.gravity))
        if b.force_limit <= weight:
            raise fail(
                f"{p}.force_limit",
                f"{b.force_limit} N cannot hold the body against gravity "
                f"(mass*|g| = {weight:.4g} N)",
            )
        vector(b.position, 3, f"{p}.position")
        for key, limit in _VELOCITY_LIMITS:
            if getattr(b, key) is not None:
                norm_in_range(vector(getattr(b, key), 3, f"{p}.{key}"), limit, f"{p}.{key}")
        quaternion(b.orientation, f"{p}.orientation")
        check_inside(b.position, s.workspace, f"{p}.position")
        if not b.goals:
            raise fail(f"{p}.goals", "empty goal list; every body needs at least one goal")
        if len(b.goals) > MAX_GOALS:
            raise fail(f"{p}.goals", f"{len(b.goals)} goals; at most {MAX_GOALS} per body")
        for j, g in enumerate(b.goals):
            _validate_goal(g, f"{p}.goals[{j}]", prop_names, s.workspace, s.resolved)
    seen = set(names)
    for i, pr in enumerate(s.props):
        p = f"props[{i}]"
        if not isinstance(pr.name, str) or not pr.name or pr.name in seen:
            raise fail(f"{p}.name", f"expected a unique non-empty string, got {show(pr.name)}")
        seen.add(pr.name)
        _validate_shape(pr.shape, pr.size, p)
        _validate_color(pr.color, f"{p}.color")
        coords_in_range(vector(pr.position, 3, f"{p}.position"), f"{p}.position")
        norm_in_range(vector(pr.velocity, 3, f"{p}.velocity"), "prop_velocity", f"{p}.velocity")
        if len(pr.waypoints) > MAX_WAYPOINTS:
            raise fail(f"{p}.waypoints", f"{len(pr.waypoints)} waypoints; at most {MAX_WAYPOINTS}")
        last = -math.inf
        for k, (t, pos) in enumerate(pr.waypoints):
            wp = f"{p}.waypoints[{k}]"
            t = number(t, f"{wp}.time")
            if not abs(t) <= LIMITS["time"][1]:
                raise fail(f"{wp}.time", f"{show(t)} is outside +-{limit_text('time')}")
            if t <= last:
                raise fail(f"{wp}.time", f"{t} is not after the previous time {last}")
            coords_in_range(vector(pos, 3, f"{wp}.position"), f"{wp}.position")
            last = t


def _validate_shape(shape: Any, size: tuple[float, ...], p: str) -> None:
    if not isinstance(shape, str) or shape not in SHAPES:
        raise fail(f"{p}.shape", f"unknown shape {show(shape)}; expected one of {sorted(SHAPES)}")
    need = SHAPES[shape]
    if len(size) != len(need):
        raise fail(f"{p}.size", f"a {shape} needs {len(need)} numbers {need}, got {list(size)}")
    for k, v in enumerate(size):
        in_range(number(v, f"{p}.size[{k}]", positive=True), "size", f"{p}.size[{k}]")


def _validate_color(color: Sequence[float], path: str) -> None:
    for x in vector(color, 4, path):
        in_range(x, "color", path)


def check_inside(pos: Sequence[float], ws: tuple[Vec3, Vec3], path: str) -> None:
    if any(not (lo < x < hi) for x, lo, hi in zip(pos, ws[0], ws[1], strict=True)):
        raise fail(path, f"{tuple(pos)} lies outside the workspace {ws[0]} .. {ws[1]}")


def _validate_goal(
    g: Goal, p: str, prop_names: set[str], ws: tuple[Vec3, Vec3], resolved: bool
) -> None:
    if not (g.has_position or g.has_orientation):
        raise fail(p, "a goal needs a nail, an orientation or a relative_rotation (none given)")
    if g.nail is not None and g.nail_prop is not None and not resolved:
        raise fail(f"{p}.nail", "give either a nail or a prop to intercept, not both")
    if g.nail is not None:
        vector(g.nail, 3, f"{p}.nail")
        check_inside(g.nail, ws, f"{p}.nail")
    if g.nail_prop is not None and g.nail_prop not in prop_names:
        raise fail(f"{p}.nail.prop", f"refers to unknown prop {show(g.nail_prop)}")
    norm_in_range(vector(g.point, 3, f"{p}.point"), "point", f"{p}.point")
    if g.orientation is not None and g.relative_rotation is not None:
        raise fail(p, "give either orientation or relative_rotation, not both")
    if g.orientation is not None:
        quaternion(g.orientation, f"{p}.orientation")
    if g.relative_rotation is not None:
        rel = vector(g.relative_rotation, 3, f"{p}.relative_rotation")
        norm_in_range(rel, "relative_rotation", f"{p}.relative_rotation")
    w = number(g.weight, f"{p}.weight")
    if w <= 0:
        raise fail(f"{p}.weight", f"routing weight must be > 0, got {show(w)}")
    in_range(w, "weight", f"{p}.weight")
    if g.time is not None:
        t = number(g.time, f"{p}.time")
        if t <= 0:
            raise fail(f"{p}.time", f"{t} is not after the start time 0")
        in_range(t, "time", f"{p}.time")
    if g.nail_prop is not None and not g.is_critical:
        raise fail(f"{p}.time", "an interception goal (nail bound to a prop) must be time-critical")
