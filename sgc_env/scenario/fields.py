"""The scenario's fields: shapes, the LIMITS table and the checks that turn raw values into typed
ones with a ScenarioError naming the field path.

Numbers are checked against ``LIMITS`` (name -> low, high, unit, where the bound comes from),
so that nothing that loads can overflow the float32 observation (bounds +-1e5), leave what
PyBullet simulates faithfully, or make the work of loading and running unbounded.
"""

from __future__ import annotations

import math
import reprlib
from collections.abc import Mapping, Sequence
from collections.abc import Set as AbstractSet
from typing import Any

import numpy as np

from sgc_env.scenario.bounded import FileLimitError, check_count, escaped
from sgc_env.scenario.caps import cap
from sgc_env.scenario.model import Quat, ScenarioError

__all__ = [
    "FIELDS", "LIMITS", "MAX_EPISODE_STEPS", "MAX_GOALS", "MAX_HELIX_TURNS", "MAX_PATH_SAMPLES",
    "MAX_WAYPOINTS", "PATH_GOAL_KEYS", "SHAPES", "TIME_GRID_MODES", "WORKSPACE_LIMIT", "check_cap",
    "check_keys", "as_float", "coords_in_range", "fail", "field_keys", "in_range", "limit_text",
    "mapping", "norm_in_range", "number", "quaternion", "require", "show", "vector",
]  # fmt: skip

SHAPES: dict[str, tuple[str, ...]] = {
    "sphere": ("radius",),
    "rod": ("length", "radius"),
    "box": ("half_x", "half_y", "half_z"),
}
TIME_GRID_MODES = ("reject", "snap")
WORKSPACE_LIMIT = 1e4  # keeps every observation entry inside the env's +-1e5 bounds
MAX_EPISODE_STEPS = 100_000  # control ticks; the harness's default episode cap
MAX_PATH_SAMPLES = cap("path_samples")
MAX_GOALS = cap("goals")  # per scenario, after path goals expand
MAX_WAYPOINTS = cap("prop_waypoints")  # per prop
MAX_HELIX_TURNS = cap("helix_turns")

FIELDS: dict[str, str] = {
    "name": "text",
    "bodies": "list",
    "props": "list?",
    "goals": "mapping?",
    "gravity": "vec3",
    "workspace": "mapping",
    "workspace.low": "vec3",
    "workspace.high": "vec3",
    "margin": "number",
    "control_frequency": "integer",
    "time_grid": "choice",
    "allow_saturation": "flag",
    "end_velocity_rule": "choice",
    "bodies[]": "mapping",
    "bodies[].name": "text",
    "bodies[].shape": "choice",
    "bodies[].size": "size",
    "bodies[].mass": "number",
    "bodies[].position": "vec3",
    "bodies[].orientation": "quat",
    "bodies[].linear_velocity": "vec3",
    "bodies[].angular_velocity": "vec3",
    "bodies[].color": "color",
    "bodies[].force_limit": "number",
    "bodies[].torque_limit": "number",
    "bodies[].goals": "list",
    "bodies[].end_velocity": "vec3?",
    "bodies[].end_angular_velocity": "vec3?",
    "bodies[].collisions": "flag",
    "bodies[].goals[]": "mapping",
    "bodies[].goals[].nail": "vec3",
    "bodies[].goals[].point": "vec3",
    "bodies[].goals[].orientation": "quat?",
    "bodies[].goals[].relative_rotation": "vec3?",
    "bodies[].goals[].time": "number?",
    "bodies[].goals[].critical": "flag?",
    "bodies[].goals[].weight": "number",
    "bodies[].goals[].path": "mapping",
    "bodies[].goals[].samples": "integer",
    "props[]": "mapping",
    "props[].name": "text",
    "props[].shape": "choice",
    "props[].size": "size",
    "props[].color": "color",
    "props[].position": "vec3",
    "props[].velocity": "vec3",
    "props[].waypoints": "list",
    "props[].collisions": "flag",
    "props[].waypoints[]": "mapping",
    "props[].waypoints[].time": "number",
    "props[].waypoints[].position": "vec3",
}
"""Every field a scenario file may hold, by path (``[]``: any list item), and its kind:
``text``, ``choice`` (one of some names), ``number``, ``integer``, ``flag`` (true/false),
``vec3``, ``quat``, ``color`` (3 or 4 numbers), ``size`` (a number or a list), ``list``,
``mapping``; ``?`` allows null. The parser takes each mapping's keys from here and the tests
generate a wrong value of every type for every field from it. A goal with a ``path`` is a
point-to-path goal (``path``, ``samples``, ``point``, ``time``, ``weight``); a ``nail`` may
also be ``{prop: name}`` (interception)."""

PATH_GOAL_KEYS = frozenset({"path", "samples", "point", "time", "weight"})


def field_keys(parent: str) -> frozenset[str]:
    """The keys :data:`FIELDS` allows in the mapping at ``parent`` (``""``: the scenario)."""
    prefix = f"{parent}." if parent else ""
    return frozenset(
        p[len(prefix) :] for p in FIELDS if p.startswith(prefix) and "." not in p[len(prefix) :]
        and not p.endswith("[]")
    )  # fmt: skip


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


# ---------------------------------------------------------------- parsing helpers


def fail(path: str, msg: str) -> ScenarioError:
    return ScenarioError(f"{path}: {msg}")


def number(value: Any, path: str, *, positive: bool = False, nonneg: bool = False) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float):
        kind = "a positive number" if positive else "a number"
        raise fail(path, f"expected {kind}, got {show(value)}{quoted_hint(value)}")
    v = as_float(value, path)
    if not math.isfinite(v):
        raise fail(path, f"expected a finite number, got {show(value)}")
    if positive and v <= 0:
        raise fail(path, f"expected a positive number, got {v!r}")
    if nonneg and v < 0:
        raise fail(path, f"expected a number >= 0, got {v!r}")
    return v


def as_float(value: float | np.floating | np.integer, path: str) -> float:
    """``float(value)``, or a ScenarioError for an integer too large for a float."""
    try:
        return float(value)
    except OverflowError:
        raise fail(
            path, f"{show(value)} is too large for a number (at most about 1.8e308)"
        ) from None


_SHORT = reprlib.Repr()
_SHORT.maxstring = _SHORT.maxother = 120
_SHORT.maxlist = _SHORT.maxtuple = _SHORT.maxdict = 10


def show(value: Any) -> str:
    """``repr(value)`` cut short and escaped onto one line (a value from a file may be huge or
    hold newlines and terminal escapes), and an integer of hundreds of digits as its size
    (Python refuses to print integers of more than 4300 digits)."""
    if isinstance(value, int) and not isinstance(value, bool) and abs(value) > 10**20:
        return f"an integer of about {int(value.bit_length() * 0.30103) + 1} digits"
    try:
        return escaped(_SHORT.repr(value))
    except ValueError:  # an integer of more than 4300 digits inside a list
        return "a value too large to print"


def quoted_hint(value: Any) -> str:
    """Why a number arrived as a string: it was quoted in the YAML file."""
    if isinstance(value, str):
        try:
            float(value)
        except ValueError:
            return ""
        return " (a string: YAML reads a quoted number as text; remove the quotes)"
    return ""


def vector(value: Any, n: int, path: str) -> tuple[float, ...]:
    if value.__class__ is tuple and len(value) == n:  # a resolved scene's: finite floats, as is
        for x in value:
            if x.__class__ is not float or x - x != 0.0:  # not a float, or NaN or infinite
                break
        else:
            return value
    if isinstance(value, str | bytes) or not isinstance(value, Sequence | np.ndarray):
        raise fail(path, f"expected a list of {n} numbers, got {show(value)}")
    if len(value) != n:
        raise fail(path, f"expected {n} numbers, got {len(value)}")
    out = []
    for x in value:
        if isinstance(x, bool) or not isinstance(x, int | float | np.floating | np.integer):
            raise fail(
                path, f"expected {n} numbers, got [{', '.join(map(show, value))}]{quoted_hint(x)}"
            )
        out.append(as_float(x, path))
    if any(math.isnan(x) for x in out):
        raise fail(path, "contains NaN")
    if any(math.isinf(x) for x in out):
        raise fail(path, "contains an infinite value")
    return tuple(out)


def quaternion(value: Any, path: str) -> Quat:
    q = vector(value, 4, path)
    norm = math.sqrt(sum(x * x for x in q))
    if abs(norm - 1.0) > 1e-3:
        raise fail(
            path, f"bad quaternion: norm {norm:.6g}, expected a unit quaternion (x, y, z, w)"
        )
    return tuple(x / norm for x in q)  # type: ignore[return-value]


def mapping(value: Any, path: str) -> Mapping[str, Any]:
    if not isinstance(value, Mapping):
        raise fail(path, f"expected a mapping, got {type(value).__name__}")
    return value


def check_keys(d: Mapping[str, Any], allowed: AbstractSet[str], path: str) -> None:
    unknown = sorted(set(d) - allowed, key=str)  # YAML keys may be numbers or null
    if unknown:
        raise fail(path, f"unknown field(s) {unknown}; expected some of {sorted(allowed)}")


def require(d: Mapping[str, Any], key: str, path: str) -> Any:
    if key not in d:
        raise fail(f"{path}.{key}" if path else key, "missing required field")
    return d[key]


def limit_text(key: str) -> str:
    lo, hi, unit, why = LIMITS[key]
    unit = f" {unit}" if unit else ""
    return f"[{lo:g}, {hi:g}]{unit} ({why})"


def in_range(value: float, key: str, path: str) -> float:
    """``value`` inside ``LIMITS[key]``, else a message with the bound and its reason."""
    lo, hi, unit, _ = LIMITS[key]
    if not lo <= value <= hi:
        raise fail(path, f"{show(value)} is outside {limit_text(key)}")
    return value


def norm_in_range(vec: Sequence[float], key: str, path: str) -> None:
    norm = math.sqrt(math.fsum(x * x for x in vec))
    if not math.isfinite(norm) or norm > LIMITS[key][1]:
        raise fail(path, f"magnitude {norm:.6g} of {tuple(vec)} is outside {limit_text(key)}")


def check_cap(count: int, name: str, path: str) -> None:
    """``count`` within cap ``name`` of :data:`~sgc_env.scenario.caps.CAPS`, else a
    ScenarioError naming ``path``."""
    try:
        check_count(count, name, path)
    except FileLimitError as exc:
        raise ScenarioError(str(exc)) from None


def coords_in_range(vec: Sequence[float], path: str) -> None:
    for x in vec:
        in_range(x, "coordinate", path)
