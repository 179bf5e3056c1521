"""Plain data (as loaded from YAML) -> an unresolved :class:`Scenario`, checking every type.

Each value is checked where it enters, and every error names its field path
(``bodies[0].goals[1].time``).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import replace
from typing import Any

import numpy as np

from sgc_env.scenario.bounded import escaped
from sgc_env.scenario.curves import parametric_curve, path_goals
from sgc_env.scenario.fields import (
    MAX_HELIX_TURNS,
    MAX_PATH_SAMPLES,
    PATH_GOAL_KEYS,
    check_cap,
    check_keys,
    fail,
    field_keys,
    mapping,
    number,
    quaternion,
    require,
    show,
    vector,
)
from sgc_env.scenario.model import Body, Goal, Prop, Scenario

__all__ = ["scenario_from_dict"]

_GOAL_KEYS = field_keys("bodies[].goals[]") - {"path", "samples"}
_BODY_KEYS = field_keys("bodies[]")
_PROP_KEYS = field_keys("props[]")
_SCENARIO_KEYS = field_keys("")


def _parse_goals(raw: Any, path: str) -> tuple[Goal, ...]:
    if not isinstance(raw, list):
        raise fail(path, f"expected a list of goals, got {type(raw).__name__}")
    check_cap(len(raw), "goals", path)
    goals: list[Goal] = []
    for j, g in enumerate(raw):
        p = f"{path}[{j}]"
        g = mapping(g, p)
        if "path" in g:
            check_keys(g, PATH_GOAL_KEYS, p)
            goals.extend(_parse_path_goal(g, p))
            continue
        check_keys(g, _GOAL_KEYS, p)
        nail, nail_prop = None, None
        if "nail" in g:
            if isinstance(g["nail"], Mapping):
                spec = g["nail"]
                check_keys(spec, {"prop"}, f"{p}.nail")
                nail_prop = str(require(spec, "prop", f"{p}.nail"))
            else:
                nail = vector(g["nail"], 3, f"{p}.nail")
        time = None if g.get("time") is None else number(g["time"], f"{p}.time")
        critical = g.get("critical")
        if critical is not None and not isinstance(critical, bool):
            raise fail(f"{p}.critical", f"expected true or false, got {show(critical)}")
        goals.append(
            Goal(
                nail=nail,  # type: ignore[arg-type]
                nail_prop=nail_prop,
                point=vector(g.get("point", (0, 0, 0)), 3, f"{p}.point"),  # type: ignore[arg-type]
                orientation=None
                if g.get("orientation") is None
                else quaternion(g["orientation"], f"{p}.orientation"),
                relative_rotation=None
                if g.get("relative_rotation") is None
                else vector(g["relative_rotation"], 3, f"{p}.relative_rotation"),  # type: ignore[arg-type]
                time=time,
                critical=critical,
                weight=number(g.get("weight", 1.0), f"{p}.weight"),
            )
        )
    return tuple(goals)


_PATH_PARAMS: dict[str, tuple[frozenset[str], frozenset[str]]] = {
    "line": (frozenset({"start", "end"}), frozenset()),
    "arc": (frozenset({"center", "radius", "start_angle", "end_angle"}), frozenset({"height"})),
    "helix": (frozenset({"center", "radius", "turns", "height"}), frozenset({"start_angle"})),
    "polyline": (frozenset({"waypoints"}), frozenset()),
}
"""Curve -> (required, optional) parameters of a ``path:`` mapping besides ``curve``."""
_PATH_VECTORS = frozenset({"start", "end", "center"})


def _path_params(spec: Mapping[str, Any], p: str) -> tuple[str, dict[str, Any]]:
    """The curve's name and its parameters, each checked for type, finiteness and caps."""
    kind = require(spec, "curve", p)
    if not isinstance(kind, str) or kind not in _PATH_PARAMS:
        raise fail(f"{p}.curve", f"unknown curve {show(kind)}; expected one of "
                                 f"{', '.join(_PATH_PARAMS)}")  # fmt: skip
    needed, optional = _PATH_PARAMS[kind]
    check_keys(spec, needed | optional | {"curve"}, p)
    params: dict[str, Any] = {}
    for key in sorted(needed | (optional & set(spec))):
        value, where = require(spec, key, p), f"{p}.{key}"
        if key in _PATH_VECTORS:
            params[key] = vector(value, 3, where)
        elif key == "waypoints":
            if isinstance(value, str | bytes) or not isinstance(value, list) or len(value) < 2:
                raise fail(where, f"expected a list of at least 2 points, got {show(value)}")
            check_cap(len(value), "polyline_points", where)
            params[key] = [vector(w, 3, f"{where}[{i}]") for i, w in enumerate(value)]
        else:
            params[key] = number(value, where)
    turns = params.get("turns")
    if turns is not None and not abs(turns) <= MAX_HELIX_TURNS:
        raise fail(f"{p}.turns", f"{show(turns)}: at most {MAX_HELIX_TURNS} turns")
    return kind, params


def _parse_path_goal(g: Mapping[str, Any], p: str) -> tuple[Goal, ...]:
    spec = mapping(g["path"], f"{p}.path")
    samples = require(g, "samples", p)
    if isinstance(samples, bool) or not isinstance(samples, int) or samples < 1:
        raise fail(f"{p}.samples", f"expected an integer >= 1, got {show(samples)}")
    if samples > MAX_PATH_SAMPLES:
        raise fail(
            f"{p}.samples",
            f"{samples} samples; at most {MAX_PATH_SAMPLES} (each sample is a goal of its own, "
            "and needs at least one control tick)",
        )
    kind, params = _path_params(spec, f"{p}.path")
    curve = parametric_curve(kind, **params)
    with np.errstate(all="ignore"):
        pts = np.asarray([curve(s) for s in (0.0, 0.5, 1.0)], float)
    if not np.all(np.isfinite(pts)):
        raise fail(f"{p}.path", "curve gives non-finite points")
    time = None if g.get("time") is None else number(g["time"], f"{p}.time")
    return path_goals(
        curve,
        samples,
        time=time,
        point=vector(g.get("point", (0, 0, 0)), 3, f"{p}.point"),  # type: ignore[arg-type]
        weight=number(g.get("weight", 1.0), f"{p}.weight"),
    )


def _goal_count(raw: Any) -> int:
    """Goals a goal list stands for once its path goals expand (an unreadable ``samples``
    counts 1: the parser names it)."""
    if not isinstance(raw, list):
        return 0
    count = 0
    for g in raw:
        samples: Any = g.get("samples") if isinstance(g, Mapping) and "path" in g else 1
        ok = isinstance(samples, int) and not isinstance(samples, bool)
        count += samples if ok and 1 <= samples <= MAX_PATH_SAMPLES else 1
    return count


def _check_counts(d: Mapping[str, Any], bodies: list[Any], props: Any) -> None:
    """Bodies, props and goals (after path expansion) within their caps, before any parsing."""
    check_cap(len(bodies), "bodies", "bodies")
    if isinstance(props, list):
        check_cap(len(props), "props", "props")
    lists = {f"bodies[{i}].goals": b.get("goals") for i, b in enumerate(bodies)
             if isinstance(b, Mapping)}  # fmt: skip
    extra = d.get("goals")
    if isinstance(extra, Mapping):
        lists.update((f"goals.{escaped(k)}", v) for k, v in extra.items())
    counts = {where: _goal_count(raw) for where, raw in lists.items()}
    for where, count in counts.items():
        check_cap(count, "goals", where)
    check_cap(sum(counts.values()), "goals", "goals")


def _size(value: Any, path: str) -> tuple[float, ...]:
    if isinstance(value, int | float) and not isinstance(value, bool):
        value = [value]
    if not isinstance(value, list | tuple):
        raise fail(path, f"expected a list of numbers, got {show(value)}")
    return tuple(number(v, f"{path}[{i}]") for i, v in enumerate(value))


def _name(value: Any, path: str) -> str:
    if not isinstance(value, str) or not value:
        raise fail(path, f"expected a non-empty string, got {show(value)}")
    return value


def _bool(value: Any, path: str) -> bool:
    if not isinstance(value, bool):
        raise fail(path, f"expected true or false, got {show(value)}")
    return value


def _parse_body(d: Any, path: str) -> Body:
    d = mapping(d, path)
    check_keys(d, _BODY_KEYS, path)
    kw: dict[str, Any] = {"name": _name(require(d, "name", path), f"{path}.name")}
    if "shape" in d:
        kw["shape"] = d["shape"]
    if "size" in d:
        kw["size"] = _size(d["size"], f"{path}.size")
    for key in ("mass", "force_limit", "torque_limit"):
        if key in d:
            kw[key] = number(d[key], f"{path}.{key}")
    for key in ("position", "linear_velocity", "angular_velocity"):
        if key in d:
            kw[key] = vector(d[key], 3, f"{path}.{key}")
    for key in ("end_velocity", "end_angular_velocity"):
        if d.get(key) is not None:
            kw[key] = vector(d[key], 3, f"{path}.{key}")
    if "orientation" in d:
        kw["orientation"] = quaternion(d["orientation"], f"{path}.orientation")
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
    return vector(value, 4, path)  # type: ignore[return-value]


def _parse_prop(d: Any, path: str) -> Prop:
    d = mapping(d, path)
    check_keys(d, _PROP_KEYS, path)
    kw: dict[str, Any] = {"name": _name(require(d, "name", path), f"{path}.name")}
    if "shape" in d:
        kw["shape"] = d["shape"]
    if "size" in d:
        kw["size"] = _size(d["size"], f"{path}.size")
    if "color" in d:
        kw["color"] = _color(d["color"], f"{path}.color")
    for key in ("position", "velocity"):
        if key in d:
            kw[key] = vector(d[key], 3, f"{path}.{key}")
    if "collisions" in d:
        kw["collisions"] = _bool(d["collisions"], f"{path}.collisions")
    if "waypoints" in d:
        wps = d["waypoints"]
        if not isinstance(wps, list) or not wps:
            raise fail(f"{path}.waypoints", "expected a non-empty list of {time, position}")
        check_cap(len(wps), "prop_waypoints", f"{path}.waypoints")
        out = []
        for i, w in enumerate(wps):
            wp = f"{path}.waypoints[{i}]"
            w = mapping(w, wp)
            check_keys(w, field_keys("props[].waypoints[]"), wp)
            out.append(
                (
                    number(require(w, "time", wp), f"{wp}.time"),
                    vector(require(w, "position", wp), 3, f"{wp}.position"),
                )
            )
        kw["waypoints"] = tuple(out)
    return Prop(**kw)


def scenario_from_dict(data: Any, *, name: str | None = None) -> Scenario:
    """Build an unresolved scenario from plain data (as loaded from YAML), checking types."""
    d = mapping(data, "scenario")
    check_keys(d, _SCENARIO_KEYS, "scenario")
    bodies_raw = require(d, "bodies", "")
    if not isinstance(bodies_raw, list) or not bodies_raw:
        raise fail("bodies", "expected a non-empty list of bodies")
    _check_counts(d, bodies_raw, d.get("props"))
    bodies = [_parse_body(b, f"bodies[{i}]") for i, b in enumerate(bodies_raw)]
    if d.get("goals") is not None:
        extra = mapping(d["goals"], "goals")
        names = [b.name for b in bodies]
        for body_name, goal_list in extra.items():
            if body_name not in names:
                raise fail(
                    "goals", f"goals refer to unknown body {show(body_name)}; bodies: {names}"
                )
            i = names.index(body_name)
            new = _parse_goals(goal_list, f"goals.{body_name}")
            bodies[i] = replace(bodies[i], goals=bodies[i].goals + new)
    props_raw = d.get("props") or []
    if not isinstance(props_raw, list):
        raise fail("props", f"expected a list of props, got {type(props_raw).__name__}")
    kw: dict[str, Any] = {
        "bodies": tuple(bodies),
        "props": tuple(_parse_prop(p, f"props[{i}]") for i, p in enumerate(props_raw)),
        "name": _name(d["name"], "name") if "name" in d else (name or "scenario"),
    }
    if "gravity" in d:
        kw["gravity"] = vector(d["gravity"], 3, "gravity")
    if "workspace" in d:
        ws = mapping(d["workspace"], "workspace")
        check_keys(ws, field_keys("workspace"), "workspace")
        kw["workspace"] = (
            vector(require(ws, "low", "workspace"), 3, "workspace.low"),
            vector(require(ws, "high", "workspace"), 3, "workspace.high"),
        )
    if "margin" in d:
        kw["margin"] = number(d["margin"], "margin", nonneg=True)
    if "control_frequency" in d:
        cf = d["control_frequency"]
        if isinstance(cf, bool) or not isinstance(cf, int) or cf <= 0:
            raise fail("control_frequency", f"expected a positive integer (Hz), got {show(cf)}")
        kw["control_frequency"] = cf
    if "time_grid" in d:
        kw["time_grid"] = d["time_grid"]
    if "allow_saturation" in d:
        kw["allow_saturation"] = _bool(d["allow_saturation"], "allow_saturation")
    if "end_velocity_rule" in d:
        kw["end_velocity_rule"] = d["end_velocity_rule"]
    return Scenario(**kw)
