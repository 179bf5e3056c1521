"""Scenario data model: bodies, goal sequences, kinematic props; YAML loading and validation.

A scenario is plain frozen data. ``resolve_scenario`` turns a user scenario into the form the
environment runs: every goal gets a time on the control grid (non-critical times from the
routing weights of ``sgc_env.paper.routing``), nails bound to props are computed from the
prop's scripted path, and every field is checked with a message that names the field path.

Numbers are checked against ``LIMITS`` (name -> low, high, unit, where the bound comes from),
so that nothing that loads can overflow the float32 observation (bounds +-1e5), leave what
PyBullet simulates faithfully, or make the work of loading and running unbounded. After
resolution the analytic plan is checked against the force and torque limits, the workspace and
PyBullet's speed clamps (:mod:`sgc_env.feasibility`); ``allow_saturation: true`` opts out of
the force and torque part for users who want saturated actuators.

YAML: the loader reads numbers as YAML 1.2 does, so ``1e0`` is the float 1.0 (plain YAML 1.1,
PyYAML's default, needs a dot and reads it as a string).
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from functools import lru_cache
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from sgc_env.paper import quaternion as quat
from sgc_env.paper.end_rules import DEFAULT_END_RULE, END_RULES
from sgc_env.paper.routing import resolve_goal_times

__all__ = [
    "SHAPES",
    "Body",
    "Goal",
    "Prop",
    "Scenario",
    "ScenarioError",
    "builtin_scenarios",
    "load_scenario",
    "parametric_curve",
    "path_goals",
    "resolve_scenario",
    "scenario_from_dict",
]

SHAPES: dict[str, tuple[str, ...]] = {
    "sphere": ("radius",),
    "rod": ("length", "radius"),
    "box": ("half_x", "half_y", "half_z"),
}
TIME_GRID_MODES = ("reject", "snap")
_TICK_TOL = 1e-9
WORKSPACE_LIMIT = 1e4  # keeps every observation entry inside the env's +-1e5 bounds
MAX_EPISODE_STEPS = 100_000  # control ticks; the harness's default episode cap
MAX_PATH_SAMPLES = 1_000
MAX_GOALS = 10_000  # per body
MAX_WAYPOINTS = 10_000  # per prop
MAX_HELIX_TURNS = 1_000

LIMITS: dict[str, tuple[float, float, str, str]] = {
    "mass": (1e-6, 1e6, "kg",
             "PyBullet makes a body of mass <= ~1e-16 static; 1e-6 keeps ten orders of margin"),
    "size": (1e-3, 1e3, "m",
             "inertia ~ m size^2 must stay far from underflow; a body fits the workspace"),
    "force_limit": (1e-9, 1e7, "N", "forces are reported in float32 (7 significant digits)"),
    "torque_limit": (1e-9, 1e7, "N m", "torques are reported in float32 (7 significant digits)"),
    "speed": (0.0, 90.0, "m/s", "PyBullet clamps linear speed at 100 m/s; the env ends at 90"),
    "spin": (0.0, 99.0, "rad/s", "PyBullet clamps angular speed at 100 rad/s"),
    "coordinate": (-WORKSPACE_LIMIT, WORKSPACE_LIMIT, "m",
                   "positions and deviations stay inside the observation bounds +-1e5"),
    "point": (0.0, WORKSPACE_LIMIT, "m",
              "the tracked point's offset is observed (bounds +-1e5)"),
    "time": (0.0, 1e4, "s",
             "float32 time in the observation still resolves 1 ms; the episode cap is "
             f"{MAX_EPISODE_STEPS} ticks"),
    "margin": (0.0, 1e3, "s", "the episode runs this long after the last goal"),
    "relative_rotation": (0.0, 64 * math.pi, "rad",  # = paper.orientation.MAX_RELATIVE_ROTATION
                          "32 turns (96 planner courses of 2 pi / 3) per goal"),
    "gravity": (0.0, 1e3, "m/s^2", "about 100 g; forces to hold a body must stay reportable"),
    "weight": (1e-9, 1e9, "", "routing divides by weights; their ratios set goal times"),
    "control_frequency": (1, 1000, "Hz", "the simulation runs an integer multiple of it"),
    "color": (0.0, 1.0, "", "RGBA components"),
    "prop_velocity": (0.0, 1e3, "m/s", "a prop must stay near the workspace for its episode"),
}  # fmt: skip

Vec3 = tuple[float, float, float]
Quat = tuple[float, float, float, float]


class ScenarioError(ValueError):
    """A scenario is malformed; the message starts with the offending field path."""


@dataclass(frozen=True)
class Goal:
    """One goal: a point-to-nail part, an orientation part, or both, with a time.

    ``relative_rotation`` is a world-frame rotation vector applied to the previous orientation
    goal (or the initial orientation); it may be longer than pi (a somersault). ``nail_prop``
    binds the nail to a prop's position at the goal time (interception). ``critical`` defaults
    to "a time is given"; non-critical goals get their time from routing ``weight``.
    """

    nail: Vec3 | None = None
    point: Vec3 = (0.0, 0.0, 0.0)
    orientation: Quat | None = None
    relative_rotation: Vec3 | None = None
    time: float | None = None
    critical: bool | None = None
    weight: float = 1.0
    nail_prop: str | None = None

    @property
    def has_position(self) -> bool:
        return self.nail is not None or self.nail_prop is not None

    @property
    def has_orientation(self) -> bool:
        return self.orientation is not None or self.relative_rotation is not None

    @property
    def is_critical(self) -> bool:
        return self.time is not None if self.critical is None else bool(self.critical)


@dataclass(frozen=True)
class Body:
    """A rigid body driven by a force and a torque, with its goal sequence."""

    name: str
    shape: str = "sphere"
    size: tuple[float, ...] = (0.05,)
    mass: float = 1.0
    position: Vec3 = (0.0, 0.0, 0.0)
    orientation: Quat = (0.0, 0.0, 0.0, 1.0)
    linear_velocity: Vec3 = (0.0, 0.0, 0.0)
    angular_velocity: Vec3 = (0.0, 0.0, 0.0)
    color: tuple[float, float, float, float] = (0.2, 0.4, 0.85, 1.0)
    force_limit: float = 50.0
    torque_limit: float = 5.0
    goals: tuple[Goal, ...] = ()
    end_velocity: Vec3 | None = None
    end_angular_velocity: Vec3 | None = None
    collisions: bool = True

    @property
    def has_position_track(self) -> bool:
        return any(g.has_position for g in self.goals)

    @property
    def has_orientation_track(self) -> bool:
        return any(g.has_orientation for g in self.goals)


@dataclass(frozen=True)
class Prop:
    """A kinematic body on a scripted path: piecewise-linear ``waypoints`` ((t, (x, y, z)), ...)
    or, without waypoints, ``position + velocity * t``. Held at the ends of a waypoint path."""

    name: str
    shape: str = "sphere"
    size: tuple[float, ...] = (0.1,)
    color: tuple[float, float, float, float] = (0.9, 0.1, 0.1, 1.0)
    position: Vec3 = (0.0, 0.0, 0.0)
    velocity: Vec3 = (0.0, 0.0, 0.0)
    waypoints: tuple[tuple[float, Vec3], ...] = ()
    collisions: bool = False

    def position_at(self, t: float) -> np.ndarray:
        if not self.waypoints:
            return np.asarray(self.position, float) + np.asarray(self.velocity, float) * t
        times = [w[0] for w in self.waypoints]
        pts = np.asarray([w[1] for w in self.waypoints], float)
        return np.array([np.interp(t, times, pts[:, j]) for j in range(3)])


@dataclass(frozen=True)
class Scenario:
    """A whole scene. ``resolved`` is set by :func:`resolve_scenario` (all goal times filled).

    ``allow_saturation``: accept goals whose plan needs more force or torque than the limits
    (the actuators then saturate and goals may be missed); by default that is an error.
    """

    bodies: tuple[Body, ...]
    props: tuple[Prop, ...] = ()
    name: str = "scenario"
    gravity: Vec3 = (0.0, 0.0, -9.81)
    workspace: tuple[Vec3, Vec3] = ((-20.0, -20.0, -20.0), (20.0, 20.0, 20.0))
    margin: float = 0.25
    control_frequency: int = 60
    time_grid: str = "reject"
    end_velocity_rule: str = DEFAULT_END_RULE
    allow_saturation: bool = False
    resolved: bool = field(default=False, compare=False)

    def body_index(self, name: str) -> int:
        for i, b in enumerate(self.bodies):
            if b.name == name:
                return i
        raise KeyError(f"no body named {name!r}")


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


# ---------------------------------------------------------------- parsing helpers


def _fail(path: str, msg: str) -> ScenarioError:
    return ScenarioError(f"{path}: {msg}")


def _number(value: Any, path: str, *, positive: bool = False, nonneg: bool = False) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float):
        kind = "a positive number" if positive else "a number"
        raise _fail(path, f"expected {kind}, got {value!r}{_quoted_hint(value)}")
    v = float(value)
    if not math.isfinite(v):
        raise _fail(path, f"expected a finite number, got {value!r}")
    if positive and v <= 0:
        raise _fail(path, f"expected a positive number, got {v!r}")
    if nonneg and v < 0:
        raise _fail(path, f"expected a number >= 0, got {v!r}")
    return v


def _quoted_hint(value: Any) -> str:
    """Why a number arrived as a string: it was quoted in the YAML file."""
    if isinstance(value, str):
        try:
            float(value)
        except ValueError:
            return ""
        return " (a string: YAML reads a quoted number as text; remove the quotes)"
    return ""


def _vector(value: Any, n: int, path: str) -> tuple[float, ...]:
    if isinstance(value, str | bytes) or not isinstance(value, Sequence | np.ndarray):
        raise _fail(path, f"expected a list of {n} numbers, got {value!r}")
    if len(value) != n:
        raise _fail(path, f"expected {n} numbers, got {len(value)}")
    out = []
    for x in value:
        if isinstance(x, bool) or not isinstance(x, int | float | np.floating | np.integer):
            raise _fail(path, f"expected {n} numbers, got {list(value)!r}{_quoted_hint(x)}")
        out.append(float(x))
    if any(math.isnan(x) for x in out):
        raise _fail(path, "contains NaN")
    if any(math.isinf(x) for x in out):
        raise _fail(path, "contains an infinite value")
    return tuple(out)


def _quaternion(value: Any, path: str) -> Quat:
    q = _vector(value, 4, path)
    norm = math.sqrt(sum(x * x for x in q))
    if abs(norm - 1.0) > 1e-3:
        raise _fail(
            path, f"bad quaternion: norm {norm:.6g}, expected a unit quaternion (x, y, z, w)"
        )
    return tuple(x / norm for x in q)  # type: ignore[return-value]


def _mapping(value: Any, path: str) -> Mapping[str, Any]:
    if not isinstance(value, Mapping):
        raise _fail(path, f"expected a mapping, got {type(value).__name__}")
    return value


def _check_keys(d: Mapping[str, Any], allowed: set[str], path: str) -> None:
    unknown = sorted(set(d) - allowed)
    if unknown:
        raise _fail(path, f"unknown field(s) {unknown}; expected some of {sorted(allowed)}")


def _require(d: Mapping[str, Any], key: str, path: str) -> Any:
    if key not in d:
        raise _fail(f"{path}.{key}" if path else key, "missing required field")
    return d[key]


def _limit_text(key: str) -> str:
    lo, hi, unit, why = LIMITS[key]
    unit = f" {unit}" if unit else ""
    return f"[{lo:g}, {hi:g}]{unit} ({why})"


def _in_range(value: float, key: str, path: str) -> float:
    """``value`` inside ``LIMITS[key]``, else a message with the bound and its reason."""
    lo, hi, unit, _ = LIMITS[key]
    if not lo <= value <= hi:
        raise _fail(path, f"{value!r} is outside {_limit_text(key)}")
    return value


def _norm_in_range(vec: Sequence[float], key: str, path: str) -> None:
    norm = math.sqrt(math.fsum(x * x for x in vec))
    if not math.isfinite(norm) or norm > LIMITS[key][1]:
        raise _fail(path, f"magnitude {norm:.6g} of {tuple(vec)} is outside {_limit_text(key)}")


def _coords_in_range(vec: Sequence[float], path: str) -> None:
    for x in vec:
        _in_range(x, "coordinate", path)


_GOAL_KEYS = {"nail", "point", "orientation", "relative_rotation", "time", "critical", "weight"}
_PATH_KEYS = {"path", "samples", "point", "time", "weight"}


def _parse_goals(raw: Any, path: str) -> tuple[Goal, ...]:
    if not isinstance(raw, list):
        raise _fail(path, f"expected a list of goals, got {type(raw).__name__}")
    if len(raw) > MAX_GOALS:
        raise _fail(path, f"{len(raw)} goals; at most {MAX_GOALS} per body")
    goals: list[Goal] = []
    for j, g in enumerate(raw):
        p = f"{path}[{j}]"
        g = _mapping(g, p)
        if "path" in g:
            _check_keys(g, _PATH_KEYS, p)
            goals.extend(_parse_path_goal(g, p))
            continue
        _check_keys(g, _GOAL_KEYS, p)
        nail, nail_prop = None, None
        if "nail" in g:
            if isinstance(g["nail"], Mapping):
                spec = g["nail"]
                _check_keys(spec, {"prop"}, f"{p}.nail")
                nail_prop = str(_require(spec, "prop", f"{p}.nail"))
            else:
                nail = _vector(g["nail"], 3, f"{p}.nail")
        time = None if g.get("time") is None else _number(g["time"], f"{p}.time")
        critical = g.get("critical")
        if critical is not None and not isinstance(critical, bool):
            raise _fail(f"{p}.critical", f"expected true or false, got {critical!r}")
        goals.append(
            Goal(
                nail=nail,  # type: ignore[arg-type]
                nail_prop=nail_prop,
                point=_vector(g.get("point", (0, 0, 0)), 3, f"{p}.point"),  # type: ignore[arg-type]
                orientation=None
                if g.get("orientation") is None
                else _quaternion(g["orientation"], f"{p}.orientation"),
                relative_rotation=None
                if g.get("relative_rotation") is None
                else _vector(g["relative_rotation"], 3, f"{p}.relative_rotation"),  # type: ignore[arg-type]
                time=time,
                critical=critical,
                weight=_number(g.get("weight", 1.0), f"{p}.weight"),
            )
        )
    return tuple(goals)


def _parse_path_goal(g: Mapping[str, Any], p: str) -> tuple[Goal, ...]:
    spec = dict(_mapping(g["path"], f"{p}.path"))
    kind = _require(spec, "curve", f"{p}.path")
    samples = _require(g, "samples", p)
    if isinstance(samples, bool) or not isinstance(samples, int) or samples < 1:
        raise _fail(f"{p}.samples", f"expected an integer >= 1, got {samples!r}")
    if samples > MAX_PATH_SAMPLES:
        raise _fail(
            f"{p}.samples",
            f"{samples} samples; at most {MAX_PATH_SAMPLES} (each sample is a goal of its own, "
            "and needs at least one control tick)",
        )
    spec.pop("curve")
    turns = spec.get("turns")
    if isinstance(turns, int | float) and not isinstance(turns, bool):
        if not abs(turns) <= MAX_HELIX_TURNS:
            raise _fail(f"{p}.path.turns", f"{turns!r}: at most {MAX_HELIX_TURNS} turns")
    try:
        curve = parametric_curve(str(kind), **spec)
        pts = np.asarray([curve(s) for s in (0.0, 0.5, 1.0)], float)
    except ScenarioError as exc:
        raise _fail(f"{p}.path.curve", str(exc)) from None
    except (KeyError, TypeError, ValueError) as exc:
        raise _fail(f"{p}.path", f"bad parameters for curve {kind!r}: {exc}") from None
    if not np.all(np.isfinite(pts)):
        raise _fail(f"{p}.path", "curve gives non-finite points")
    time = None if g.get("time") is None else _number(g["time"], f"{p}.time")
    return path_goals(
        curve,
        samples,
        time=time,
        point=_vector(g.get("point", (0, 0, 0)), 3, f"{p}.point"),  # type: ignore[arg-type]
        weight=_number(g.get("weight", 1.0), f"{p}.weight"),
    )


_BODY_KEYS = {
    "name", "shape", "size", "mass", "position", "orientation", "linear_velocity",
    "angular_velocity", "color", "force_limit", "torque_limit", "goals", "end_velocity",
    "end_angular_velocity", "collisions",
}  # fmt: skip
_PROP_KEYS = {"name", "shape", "size", "color", "position", "velocity", "waypoints", "collisions"}
_SCENARIO_KEYS = {
    "name", "bodies", "props", "goals", "gravity", "workspace", "margin", "control_frequency",
    "time_grid", "allow_saturation", "end_velocity_rule",
}  # fmt: skip


def _size(value: Any, path: str) -> tuple[float, ...]:
    if isinstance(value, int | float) and not isinstance(value, bool):
        value = [value]
    if not isinstance(value, list | tuple):
        raise _fail(path, f"expected a list of numbers, got {value!r}")
    return tuple(_number(v, f"{path}[{i}]") for i, v in enumerate(value))


def _bool(value: Any, path: str) -> bool:
    if not isinstance(value, bool):
        raise _fail(path, f"expected true or false, got {value!r}")
    return value


def _parse_body(d: Any, path: str) -> Body:
    d = _mapping(d, path)
    _check_keys(d, _BODY_KEYS, path)
    name = _require(d, "name", path)
    if not isinstance(name, str) or not name:
        raise _fail(f"{path}.name", f"expected a non-empty string, got {name!r}")
    kw: dict[str, Any] = {"name": name}
    if "shape" in d:
        kw["shape"] = d["shape"]
    if "size" in d:
        kw["size"] = _size(d["size"], f"{path}.size")
    for key in ("mass", "force_limit", "torque_limit"):
        if key in d:
            kw[key] = _number(d[key], f"{path}.{key}")
    for key in ("position", "linear_velocity", "angular_velocity"):
        if key in d:
            kw[key] = _vector(d[key], 3, f"{path}.{key}")
    for key in ("end_velocity", "end_angular_velocity"):
        if d.get(key) is not None:
            kw[key] = _vector(d[key], 3, f"{path}.{key}")
    if "orientation" in d:
        kw["orientation"] = _quaternion(d["orientation"], f"{path}.orientation")
    if "color" in d:
        kw["color"] = _color(d["color"], f"{path}.color")
    if "collisions" in d:
        kw["collisions"] = _bool(d["collisions"], f"{path}.collisions")
    if "goals" in d:
        kw["goals"] = _parse_goals(d["goals"], f"{path}.goals")
    return Body(**kw)


def _color(value: Any, path: str) -> tuple[float, float, float, float]:
    if isinstance(value, list | tuple) and len(value) == 3:
        value = [*value, 1.0]
    return _vector(value, 4, path)  # type: ignore[return-value]


def _parse_prop(d: Any, path: str) -> Prop:
    d = _mapping(d, path)
    _check_keys(d, _PROP_KEYS, path)
    kw: dict[str, Any] = {"name": _require(d, "name", path)}
    if "shape" in d:
        kw["shape"] = d["shape"]
    if "size" in d:
        kw["size"] = _size(d["size"], f"{path}.size")
    if "color" in d:
        kw["color"] = _color(d["color"], f"{path}.color")
    for key in ("position", "velocity"):
        if key in d:
            kw[key] = _vector(d[key], 3, f"{path}.{key}")
    if "collisions" in d:
        kw["collisions"] = _bool(d["collisions"], f"{path}.collisions")
    if "waypoints" in d:
        wps = d["waypoints"]
        if not isinstance(wps, list) or not wps:
            raise _fail(f"{path}.waypoints", "expected a non-empty list of {time, position}")
        if len(wps) > MAX_WAYPOINTS:
            raise _fail(f"{path}.waypoints", f"{len(wps)} waypoints; at most {MAX_WAYPOINTS}")
        out = []
        for i, w in enumerate(wps):
            wp = f"{path}.waypoints[{i}]"
            w = _mapping(w, wp)
            _check_keys(w, {"time", "position"}, wp)
            out.append(
                (
                    _number(_require(w, "time", wp), f"{wp}.time"),
                    _vector(_require(w, "position", wp), 3, f"{wp}.position"),
                )
            )
        kw["waypoints"] = tuple(out)
    return Prop(**kw)


def scenario_from_dict(data: Any, *, name: str | None = None) -> Scenario:
    """Build an unresolved scenario from plain data (as loaded from YAML), checking types."""
    d = _mapping(data, "scenario")
    _check_keys(d, _SCENARIO_KEYS, "scenario")
    bodies_raw = _require(d, "bodies", "")
    if not isinstance(bodies_raw, list) or not bodies_raw:
        raise _fail("bodies", "expected a non-empty list of bodies")
    bodies = [_parse_body(b, f"bodies[{i}]") for i, b in enumerate(bodies_raw)]
    if d.get("goals") is not None:
        extra = _mapping(d["goals"], "goals")
        names = [b.name for b in bodies]
        for body_name, goal_list in extra.items():
            if body_name not in names:
                raise _fail("goals", f"goals refer to unknown body {body_name!r}; bodies: {names}")
            i = names.index(body_name)
            new = _parse_goals(goal_list, f"goals.{body_name}")
            bodies[i] = replace(bodies[i], goals=bodies[i].goals + new)
    props_raw = d.get("props") or []
    if not isinstance(props_raw, list):
        raise _fail("props", f"expected a list of props, got {type(props_raw).__name__}")
    kw: dict[str, Any] = {
        "bodies": tuple(bodies),
        "props": tuple(_parse_prop(p, f"props[{i}]") for i, p in enumerate(props_raw)),
        "name": str(d.get("name", name or "scenario")),
    }
    if "gravity" in d:
        kw["gravity"] = _vector(d["gravity"], 3, "gravity")
    if "workspace" in d:
        ws = _mapping(d["workspace"], "workspace")
        _check_keys(ws, {"low", "high"}, "workspace")
        kw["workspace"] = (
            _vector(_require(ws, "low", "workspace"), 3, "workspace.low"),
            _vector(_require(ws, "high", "workspace"), 3, "workspace.high"),
        )
    if "margin" in d:
        kw["margin"] = _number(d["margin"], "margin", nonneg=True)
    if "control_frequency" in d:
        cf = d["control_frequency"]
        if isinstance(cf, bool) or not isinstance(cf, int) or cf <= 0:
            raise _fail("control_frequency", f"expected a positive integer (Hz), got {cf!r}")
        kw["control_frequency"] = cf
    if "time_grid" in d:
        kw["time_grid"] = d["time_grid"]
    if "allow_saturation" in d:
        kw["allow_saturation"] = _bool(d["allow_saturation"], "allow_saturation")
    if "end_velocity_rule" in d:
        kw["end_velocity_rule"] = d["end_velocity_rule"]
    return Scenario(**kw)


# ---------------------------------------------------------------- semantic validation


_VELOCITY_LIMITS = (
    ("linear_velocity", "speed"), ("angular_velocity", "spin"),
    ("end_velocity", "speed"), ("end_angular_velocity", "spin"),
)  # fmt: skip


def _validate_structure(s: Scenario) -> None:
    if not s.bodies:
        raise _fail("bodies", "expected at least one body")
    if s.time_grid not in TIME_GRID_MODES:
        raise _fail("time_grid", f"expected one of {TIME_GRID_MODES}, got {s.time_grid!r}")
    if s.end_velocity_rule not in END_RULES:
        raise _fail(
            "end_velocity_rule", f"expected one of {END_RULES}, got {s.end_velocity_rule!r}"
        )
    if not (isinstance(s.control_frequency, int) and s.control_frequency > 0):
        raise _fail(
            "control_frequency", f"expected a positive integer, got {s.control_frequency!r}"
        )
    _in_range(s.control_frequency, "control_frequency", "control_frequency")
    _norm_in_range(_vector(s.gravity, 3, "gravity"), "gravity", "gravity")
    lo, hi = (
        _vector(s.workspace[0], 3, "workspace.low"),
        _vector(s.workspace[1], 3, "workspace.high"),
    )
    if any(a >= b for a, b in zip(lo, hi, strict=True)):
        raise _fail("workspace", f"low {lo} must be below high {hi} in every axis")
    if max(map(abs, lo + hi)) > WORKSPACE_LIMIT:
        raise _fail("workspace", f"must lie inside +-{WORKSPACE_LIMIT:g} m, got {lo} .. {hi}")
    _in_range(_number(s.margin, "margin", nonneg=True), "margin", "margin")
    if not isinstance(s.allow_saturation, bool):
        raise _fail("allow_saturation", f"expected true or false, got {s.allow_saturation!r}")
    names: set[str] = set()
    prop_names = {p.name for p in s.props}
    for i, b in enumerate(s.bodies):
        p = f"bodies[{i}]"
        if b.name in names or b.name in prop_names:
            raise _fail(f"{p}.name", f"duplicate name {b.name!r}")
        names.add(b.name)
        _validate_shape(b.shape, b.size, p)
        _validate_color(b.color, f"{p}.color")
        for key in ("mass", "force_limit", "torque_limit"):
            _in_range(_number(getattr(b, key), f"{p}.{key}", positive=True), key, f"{p}.{key}")
        weight = b.mass * float(np.linalg.norm(s.gravity))
        if b.force_limit <= weight:
            raise _fail(
                f"{p}.force_limit",
                f"{b.force_limit} N cannot hold the body against gravity "
                f"(mass*|g| = {weight:.4g} N)",
            )
        _vector(b.position, 3, f"{p}.position")
        for key, limit in _VELOCITY_LIMITS:
            if getattr(b, key) is not None:
                _norm_in_range(_vector(getattr(b, key), 3, f"{p}.{key}"), limit, f"{p}.{key}")
        _quaternion(b.orientation, f"{p}.orientation")
        _check_inside(b.position, s.workspace, f"{p}.position")
        if not b.goals:
            raise _fail(f"{p}.goals", "empty goal list; every body needs at least one goal")
        if len(b.goals) > MAX_GOALS:
            raise _fail(f"{p}.goals", f"{len(b.goals)} goals; at most {MAX_GOALS} per body")
        for j, g in enumerate(b.goals):
            _validate_goal(g, f"{p}.goals[{j}]", prop_names, s.workspace, s.resolved)
    seen = set(names)
    for i, pr in enumerate(s.props):
        p = f"props[{i}]"
        if not isinstance(pr.name, str) or not pr.name or pr.name in seen:
            raise _fail(f"{p}.name", f"expected a unique non-empty string, got {pr.name!r}")
        seen.add(pr.name)
        _validate_shape(pr.shape, pr.size, p)
        _validate_color(pr.color, f"{p}.color")
        _coords_in_range(_vector(pr.position, 3, f"{p}.position"), f"{p}.position")
        _norm_in_range(_vector(pr.velocity, 3, f"{p}.velocity"), "prop_velocity", f"{p}.velocity")
        if len(pr.waypoints) > MAX_WAYPOINTS:
            raise _fail(f"{p}.waypoints", f"{len(pr.waypoints)} waypoints; at most {MAX_WAYPOINTS}")
        last = -math.inf
        for k, (t, pos) in enumerate(pr.waypoints):
            wp = f"{p}.waypoints[{k}]"
            t = _number(t, f"{wp}.time")
            if not abs(t) <= LIMITS["time"][1]:
                raise _fail(f"{wp}.time", f"{t!r} is outside +-{_limit_text('time')}")
            if t <= last:
                raise _fail(f"{wp}.time", f"{t} is not after the previous time {last}")
            _coords_in_range(_vector(pos, 3, f"{wp}.position"), f"{wp}.position")
            last = t


def _validate_shape(shape: Any, size: tuple[float, ...], p: str) -> None:
    if shape not in SHAPES:
        raise _fail(f"{p}.shape", f"unknown shape {shape!r}; expected one of {sorted(SHAPES)}")
    need = SHAPES[shape]
    if len(size) != len(need):
        raise _fail(f"{p}.size", f"a {shape} needs {len(need)} numbers {need}, got {list(size)}")
    for k, v in enumerate(size):
        _in_range(_number(v, f"{p}.size[{k}]", positive=True), "size", f"{p}.size[{k}]")


def _validate_color(color: Sequence[float], path: str) -> None:
    for x in _vector(color, 4, path):
        _in_range(x, "color", path)


def _check_inside(pos: Sequence[float], ws: tuple[Vec3, Vec3], path: str) -> None:
    if any(not (lo < x < hi) for x, lo, hi in zip(pos, ws[0], ws[1], strict=True)):
        raise _fail(path, f"{tuple(pos)} lies outside the workspace {ws[0]} .. {ws[1]}")


def _validate_goal(
    g: Goal, p: str, prop_names: set[str], ws: tuple[Vec3, Vec3], resolved: bool
) -> None:
    if not (g.has_position or g.has_orientation):
        raise _fail(p, "a goal needs a nail, an orientation or a relative_rotation (none given)")
    if g.nail is not None and g.nail_prop is not None and not resolved:
        raise _fail(f"{p}.nail", "give either a nail or a prop to intercept, not both")
    if g.nail is not None:
        _vector(g.nail, 3, f"{p}.nail")
        _check_inside(g.nail, ws, f"{p}.nail")
    if g.nail_prop is not None and g.nail_prop not in prop_names:
        raise _fail(f"{p}.nail.prop", f"refers to unknown prop {g.nail_prop!r}")
    _norm_in_range(_vector(g.point, 3, f"{p}.point"), "point", f"{p}.point")
    if g.orientation is not None and g.relative_rotation is not None:
        raise _fail(p, "give either orientation or relative_rotation, not both")
    if g.orientation is not None:
        _quaternion(g.orientation, f"{p}.orientation")
    if g.relative_rotation is not None:
        rel = _vector(g.relative_rotation, 3, f"{p}.relative_rotation")
        _norm_in_range(rel, "relative_rotation", f"{p}.relative_rotation")
    w = _number(g.weight, f"{p}.weight")
    if w <= 0:
        raise _fail(f"{p}.weight", f"routing weight must be > 0, got {w!r}")
    _in_range(w, "weight", f"{p}.weight")
    if g.time is not None:
        t = _number(g.time, f"{p}.time")
        if t <= 0:
            raise _fail(f"{p}.time", f"{t} is not after the start time 0")
        _in_range(t, "time", f"{p}.time")
    if g.nail_prop is not None and not g.is_critical:
        raise _fail(
            f"{p}.time", "an interception goal (nail bound to a prop) must be time-critical"
        )


# ---------------------------------------------------------------- resolution


def _rotation_angle(qa: Sequence[float], qb: Sequence[float]) -> float:
    dot = abs(float(np.dot(qa, qb)))
    return 2.0 * math.acos(min(1.0, dot))


def _on_grid(t: float, freq: int, mode: str, path: str) -> float:
    ticks = t * freq
    k = round(ticks)
    if abs(ticks - k) <= _TICK_TOL * max(1.0, abs(ticks)):
        return k / freq
    if mode == "snap":
        k = max(k, 1)
        return k / freq
    lo, hi = math.floor(ticks) / freq, math.ceil(ticks) / freq
    raise _fail(
        path,
        f"{t} is not on the control grid (1/{freq} s); nearest ticks are {lo:.10g} and "
        f"{hi:.10g} (set time_grid: snap to round)",
    )


def _body_goal_times(b: Body, s: Scenario, freq: int, mode: str, p: str) -> list[float]:
    """Critical times on the grid, then routed non-critical times snapped to the grid."""
    times: list[float | None] = []
    critical: list[bool] = []
    distances: list[float] = []
    weights: list[float] = []
    prev_point: np.ndarray | None = None
    prev_q: Any = np.asarray(b.orientation, float)
    for j, g in enumerate(b.goals):
        gp = f"{p}.goals[{j}]"
        crit = g.is_critical
        if crit:
            if g.time is None:
                raise _fail(f"{gp}.time", "a time-critical goal needs a time")
            times.append(_on_grid(float(g.time), freq, mode, f"{gp}.time"))
        else:
            if g.time is not None and not s.resolved:
                raise _fail(
                    f"{gp}.time",
                    f"has time {g.time} but is not time-critical; "
                    "drop the time or mark it critical",
                )
            times.append(None)
        critical.append(crit)
        weights.append(float(g.weight))
        dist = 0.0
        if g.has_position:
            nail = _goal_nail(g, s, times[-1])
            if prev_point is None:
                prev_point = np.asarray(b.position, float) + quat.rotate(b.orientation, g.point)
            dist = float(np.linalg.norm(nail - prev_point)) if nail is not None else 0.0
            prev_point = nail
        if g.has_orientation:
            q: Any
            if g.relative_rotation is not None:
                angle = float(np.linalg.norm(g.relative_rotation))
                q = quat.mul(quat.exp_normalized(g.relative_rotation), prev_q)
            else:
                q = np.asarray(g.orientation, float)
                angle = _rotation_angle(prev_q, q)
            prev_q = q
            if not g.has_position:
                dist = angle
        distances.append(dist)
    for j in range(1, len(times)):
        if critical[j]:
            prev = [t for t in times[:j] if t is not None]
            if prev and times[j] <= prev[-1]:  # type: ignore[operator]
                raise _fail(
                    f"{p}.goals[{j}].time",
                    f"{times[j]} is not after the previous goal time {prev[-1]}",
                )
    try:
        resolved = resolve_goal_times(times, critical, distances, weights, start_time=0.0)
    except ValueError as exc:
        raise _fail(f"{p}.goals", str(exc)) from None
    out: list[float] = []
    last = 0.0
    for j, t in enumerate(resolved):
        t = round(float(t) * freq) / freq
        if t <= last:
            raise _fail(
                f"{p}.goals[{j}].time",
                f"routed time lands on tick {t:.10g}, not after the previous goal ({last:.10g}); "
                "use fewer goals, more time or a higher control_frequency",
            )
        out.append(t)
        last = t
    return out


def _goal_nail(g: Goal, s: Scenario, t: float | None) -> np.ndarray | None:
    if g.nail_prop is not None and t is not None:
        prop = next(pr for pr in s.props if pr.name == g.nail_prop)
        return prop.position_at(t)
    if g.nail is not None:
        return np.asarray(g.nail, float)
    return None


def _goal_at(b: Body, t: float) -> int:
    """Index of the goal whose course contains time ``t`` (the first goal not before it)."""
    for j, g in enumerate(b.goals):
        if float(g.time) >= t - 1e-9:  # type: ignore[arg-type]
            return j
    return len(b.goals) - 1


@lru_cache(maxsize=64)
def _check_plan(s: Scenario) -> None:
    """The analytic plan against the limits (cached: scenarios are frozen and hashable)."""
    from sgc_env.feasibility import body_demand

    for i, b in enumerate(s.bodies):
        p = f"bodies[{i}]"
        try:
            d = body_demand(s, b)
        except ValueError as exc:  # goals the planner cannot plan (e.g. too few ticks)
            raise _fail(f"{p}.goals", str(exc)) from None
        if d.outside_time is not None:
            raise _fail(
                f"{p}.goals[{_goal_at(b, d.outside_time)}]",
                f"the planned path leaves the workspace at t = {d.outside_time:.4g} s; "
                "widen the workspace or move the goal",
            )
        for value, when, key, what in (
            (d.speed, d.speed_time, "speed", "a speed"), (d.spin, d.spin_time, "spin", "a spin")
        ):  # fmt: skip
            if value > LIMITS[key][1]:
                raise _fail(
                    f"{p}.goals[{_goal_at(b, when)}]",
                    f"the plan needs {what} of {value:.4g} {LIMITS[key][2]} near t = "
                    f"{when:.4g} s, above {LIMITS[key][1]:g} ({LIMITS[key][3]}); give it more time",
                )
        if s.allow_saturation:
            continue
        for value, when, key, unit in (
            (d.force, d.force_time, "force_limit", "N"),
            (d.torque, d.torque_time, "torque_limit", "N m"),
        ):
            limit = float(getattr(b, key))
            if value > limit:
                raise _fail(
                    f"{p}.goals[{_goal_at(b, when)}]",
                    f"the plan needs a peak {key[:-6]} of {value:.4g} {unit} near t = "
                    f"{when:.4g} s, above {p}.{key} = {limit:g} {unit}; raise the limit, give "
                    "the goal more time, or set allow_saturation: true to accept saturation",
                )


def resolve_scenario(
    scenario: Scenario,
    *,
    control_frequency: int | None = None,
    time_grid: str | None = None,
    check_plan: bool = True,
) -> Scenario:
    """Validate ``scenario`` and fill in every goal time (on the control grid) and prop nail.

    ``control_frequency``/``time_grid`` override the scenario's. Idempotent on a resolved
    scenario (non-critical times are re-routed from the critical ones). ``check_plan``: check
    the analytic plan against the limits (see :func:`_check_plan`); callers with a cheaper
    guarantee of their own (``random_scenarios``) turn it off.
    """
    s = scenario
    if control_frequency is not None:
        s = replace(s, control_frequency=control_frequency)
    if time_grid is not None:
        s = replace(s, time_grid=time_grid)
    _validate_structure(s)
    bodies = []
    for i, b in enumerate(s.bodies):
        p = f"bodies[{i}]"
        times = _body_goal_times(b, s, s.control_frequency, s.time_grid, p)
        goals: list[Goal] = []
        for g, t in zip(b.goals, times, strict=True):
            nail = g.nail
            if g.nail_prop is not None:
                pos = _goal_nail(g, s, t)
                nail = tuple(float(x) for x in pos)  # type: ignore[union-attr,assignment]
                _check_inside(nail, s.workspace, f"{p}.goals[{len(goals)}].nail")  # type: ignore[arg-type]
            goals.append(replace(g, time=t, critical=g.is_critical, nail=nail))
        bodies.append(replace(b, goals=tuple(goals)))
    out = replace(s, bodies=tuple(bodies), resolved=True)
    last = max(round(float(g.time) * s.control_frequency) for b in bodies for g in b.goals)  # type: ignore[arg-type]
    steps = last + math.ceil(s.margin * s.control_frequency - 1e-9)
    if steps > MAX_EPISODE_STEPS:
        raise _fail(
            "goals",
            f"the episode would last {steps} control ticks (last goal at {last} ticks plus the "
            f"margin); at most {MAX_EPISODE_STEPS}: use shorter goal times or a lower "
            "control_frequency",
        )
    if check_plan:
        _check_plan(out)
    return out


# ---------------------------------------------------------------- loading


def builtin_scenarios() -> tuple[str, ...]:
    """Names of the scenarios shipped in ``sgc_env/scenarios``."""
    root = resources.files("sgc_env") / "scenarios"
    return tuple(sorted(p.name[:-5] for p in root.iterdir() if p.name.endswith(".yaml")))


def load_scenario(path_or_name: str | Path | Scenario) -> Scenario:
    """Load, validate and resolve a scenario from a YAML path or a built-in name."""
    if isinstance(path_or_name, Scenario):
        return resolve_scenario(path_or_name)
    path = Path(path_or_name)
    if path.suffix in (".yaml", ".yml") and path.exists():
        text = _read_text(path)
        name = path.stem
    else:
        res = resources.files("sgc_env") / "scenarios" / f"{path_or_name}.yaml"
        if not res.is_file():
            raise ScenarioError(
                f"no scenario file {str(path_or_name)!r} and no built-in of that name; "
                f"built-ins: {list(builtin_scenarios())}"
            )
        text = res.read_text()
        name = str(path_or_name)
    try:
        data = yaml.load(text, Loader=_Loader)  # noqa: S506 (a SafeLoader)
    except yaml.YAMLError as exc:
        raise ScenarioError(f"{name}: not valid YAML: {exc}") from None
    except RecursionError:
        raise ScenarioError(f"{name}: nested too deeply to read") from None
    try:
        return resolve_scenario(scenario_from_dict(data, name=name))
    except RecursionError:
        raise ScenarioError(f"{name}: nested too deeply to read") from None


class _Loader(yaml.SafeLoader):
    """PyYAML's safe loader with YAML 1.2 floats: ``1e0`` and ``1E-3`` are numbers (YAML 1.1
    asks for a dot and reads them as strings, which surprises everyone)."""


_Loader.add_implicit_resolver(
    "tag:yaml.org,2002:float",
    re.compile(r"^[-+]?(?:[0-9][0-9_]*)(?:\.[0-9_]*)?[eE][-+]?[0-9]+$"),
    list("-+0123456789"),
)


def _read_text(path: Path) -> str:
    """The file's text, or a ScenarioError naming the file and what is wrong with it."""
    try:
        return path.read_text(encoding="utf-8")
    except IsADirectoryError:
        raise ScenarioError(f"{path}: is a directory, not a scenario file") from None
    except UnicodeDecodeError as exc:
        raise ScenarioError(
            f"{path}: not UTF-8 text (byte {exc.start}: {exc.reason}); save it as UTF-8"
        ) from None
    except OSError as exc:
        raise ScenarioError(f"{path}: cannot read: {exc.strerror or exc}") from None
