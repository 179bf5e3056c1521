"""Every scenario field against every wrong type, generated from the one table of fields.

For each path of :data:`sgc_env.scenario.fields.FIELDS` and each wrong value (a list, a
mapping, a bool, null, a string, an integer too large for a float, NaN, inf, a nested list, and
for vectors the same inside the vector) the scenario must be refused with a ScenarioError
whose message starts with the field's path (``bodies[0].goals[1].time: ...``): never a Python
TypeError, OverflowError or a message that names another field.
"""

from __future__ import annotations

import copy
import math
import re
from typing import Any

import pytest

from sgc_env.scenario import ScenarioError, resolve_scenario, scenario_from_dict
from sgc_env.scenario.fields import FIELDS

BASE: dict[str, Any] = {
    "name": "fields",
    "control_frequency": 60,
    "margin": 0.25,
    "time_grid": "reject",
    "allow_saturation": False,
    "end_velocity_rule": "tangent",
    "gravity": [0.0, 0.0, -9.81],
    "workspace": {"low": [-5.0, -5.0, -5.0], "high": [5.0, 5.0, 6.0]},
    "goals": {},
    "bodies": [
        {
            "name": "rod",
            "shape": "rod",
            "size": [0.6, 0.03],
            "mass": 1.0,
            "position": [0.0, 0.0, 1.0],
            "orientation": [0.0, 0.0, 0.0, 1.0],
            "linear_velocity": [0.0, 0.0, 0.0],
            "angular_velocity": [0.0, 0.0, 0.0],
            "color": [0.2, 0.4, 0.8, 1.0],
            "force_limit": 100.0,
            "torque_limit": 5.0,
            "end_velocity": [0.0, 0.0, 0.0],
            "end_angular_velocity": [0.0, 0.0, 0.0],
            "collisions": True,
            "goals": [
                {"nail": [0.3, 0.0, 1.2], "time": 0.5},
                {"nail": [0.6, 0.2, 1.3], "point": [0.0, 0.0, 0.0], "time": 1.0,
                 "critical": True, "weight": 1.0},
                {"path": {"curve": "line", "start": [0.6, 0.2, 1.3], "end": [0.9, 0.2, 1.3]},
                 "samples": 2, "time": 2.0},
            ],
        }
    ],
    "props": [
        {
            "name": "fish",
            "shape": "sphere",
            "size": [0.1],
            "color": [0.9, 0.1, 0.1, 1.0],
            "position": [2.0, 0.0, 1.0],
            "velocity": [0.0, 0.0, 0.0],
            "waypoints": [
                {"time": 0.0, "position": [2.0, 0.0, 1.0]},
                {"time": 3.0, "position": [2.0, 1.0, 1.0]},
            ],
            "collisions": False,
        }
    ],
}  # fmt: skip

INDEX = {"bodies[]": 0, "props[]": 0, "waypoints[]": 1, "goals[]": 1}
"""Which item a ``[]`` of FIELDS stands for (goal 1: an index the message must get right)."""
PATH_GOAL = 2  # the point-to-path goal of BASE

WRONG: dict[str, Any] = {
    "list": [1.0, 2.0],
    "mapping": {"unknown": 1},
    "bool": True,
    "null": None,
    "string": "1.0",
    "huge int": 10**400,
    "nan": math.nan,
    "inf": math.inf,
    "nested": [[[1.0]]],
}
INSIDE = {k: v for k, v in WRONG.items() if k != "list"}
"""Wrong values for an entry of a vector (``[value, 0, 0]``)."""
ACCEPTED = {
    "text": {"string"},
    "choice": set(),
    "flag": {"bool"},
    "list": set(),
    "mapping": set(),
    "size": {"list"},  # a rod of length 1 and radius 2 is well typed
}
"""Wrong values that are right for a kind (``?`` kinds also accept null)."""


def _concrete(template: str) -> str:
    """``bodies[].goals[].time`` -> ``bodies[0].goals[1].time`` (path goal fields: goal 2)."""
    out = template
    for key, index in INDEX.items():
        name = key[:-2]
        if template.startswith("bodies[].goals[].") and template.split(".")[-1] in (
            "path",
            "samples",
        ):
            index = PATH_GOAL if name == "goals" else index
        out = out.replace(f"{name}[]", f"{name}[{index}]")
    return out


def _set(doc: dict, path: str, value: Any) -> None:
    parts = re.findall(r"[^.\[\]]+|\[\d+\]", path)
    node: Any = doc
    for part in parts[:-1]:
        node = node[int(part[1:-1])] if part.startswith("[") else node[part]
    last = parts[-1]
    if last.startswith("["):
        node[int(last[1:-1])] = value
    else:
        node[last] = value


def _cases() -> list[Any]:
    cases = []
    for template, kind in FIELDS.items():
        base_kind = kind.rstrip("?")
        accepted = set(ACCEPTED.get(base_kind, ())) | ({"null"} if kind.endswith("?") else set())
        path = _concrete(template)
        for name, value in WRONG.items():
            if name not in accepted:
                cases.append(pytest.param(path, value, id=f"{path}={name}"))
        if base_kind in ("vec3", "quat", "color"):
            for name, value in INSIDE.items():
                size = 4 if base_kind != "vec3" else 3
                vector = [value] + [0.0] * (size - 1)
                cases.append(pytest.param(path, vector, id=f"{path}=[{name}, ...]"))
    return cases


def _load(doc: dict) -> None:
    resolve_scenario(scenario_from_dict(copy.deepcopy(doc)))


def test_the_base_scenario_loads():
    _load(BASE)


def test_every_field_of_the_table_is_covered():
    assert len(_cases()) > 10 * len(FIELDS)
    assert _concrete("bodies[].goals[].time") == "bodies[0].goals[1].time"
    assert _concrete("bodies[].goals[].samples") == "bodies[0].goals[2].samples"


@pytest.mark.parametrize(("path", "value"), _cases())
def test_a_wrong_type_is_refused_naming_the_field(path, value):
    doc = copy.deepcopy(BASE)
    _set(doc, path, value)
    with pytest.raises(ScenarioError) as err:
        _load(doc)
    message = str(err.value)
    assert message.startswith(path), message
