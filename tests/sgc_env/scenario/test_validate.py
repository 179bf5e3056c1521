"""Malformed scenarios: each gives a ScenarioError whose message starts with the field path.

One table row per defect (issue 12 item 3 and the earlier bad-input list): the row's mutation
is applied to a scenario that loads, and the error must name the field it broke.
"""

from __future__ import annotations

import copy
import math
from collections.abc import Callable

import numpy as np
import pytest
import yaml

from sgc_env.scenario import (
    LIMITS,
    MAX_PATH_SAMPLES,
    Scenario,
    ScenarioError,
    load_scenario,
    resolve_scenario,
    scenario_from_dict,
)
from sgc_env.scenes import random_scenario

BASE = {
    "name": "valid",
    "bodies": [
        {
            "name": "ball",
            "shape": "sphere",
            "size": [0.05],
            "mass": 1.0,
            "position": [0, 0, 1],
            "force_limit": 60.0,
            "goals": [
                {"nail": [0.5, 0, 1], "time": 0.5},
                {"nail": [0.5, 0.5, 1]},
                {"nail": [0, 0.5, 1], "time": 1.5},
            ],
        },
        {
            "name": "rod",
            "shape": "rod",
            "size": [0.6, 0.03],
            "mass": 1.0,
            "position": [0, 0, 2],
            "torque_limit": 5.0,
            "goals": [
                {"orientation": [0, 0, 0, 1], "nail": [0, 0, 2], "time": 1.0},
                {"relative_rotation": [0, 0, 1], "time": 2.0},
            ],
        },
    ],
    "props": [{"name": "fish", "position": [1, 0, 0.5], "velocity": [0.1, 0, 0]}],
}


def load(data) -> Scenario:
    return resolve_scenario(scenario_from_dict(data))


def ball(d):
    return d["bodies"][0]


def rod(d):
    return d["bodies"][1]


def goal(d, j, body=0):
    return d["bodies"][body]["goals"][j]


def fish(d):
    return d["props"][0]


Mutation = Callable[[dict], object]

# (label, mutation, field path the message must start with, fragment the message must contain)
CASES: list[tuple[str, Mutation, str, str]] = [
    # the whole scenario
    ("unknown top field", lambda d: d.update(colour="red"), "scenario", "unknown field"),
    ("bodies missing", lambda d: d.pop("bodies"), "bodies", "missing"),
    ("bodies not a list", lambda d: d.update(bodies={"ball": 1}), "bodies", "non-empty list"),
    ("bodies empty", lambda d: d.update(bodies=[]), "bodies", "non-empty list"),
    ("gravity 2 numbers", lambda d: d.update(gravity=[0, -9.8]), "gravity", "3 numbers"),
    ("gravity NaN", lambda d: d.update(gravity=[0, 0, math.nan]), "gravity", "NaN"),
    ("gravity inf", lambda d: d.update(gravity=[0, 0, -math.inf]), "gravity", "infinite"),
    ("gravity 1e4", lambda d: d.update(gravity=[0, 0, -1e4]), "gravity", "outside"),
    ("gravity text", lambda d: d.update(gravity="down"), "gravity", "list of 3"),
    ("workspace inverted", lambda d: d.update(workspace={"low": [1, 1, 1], "high": [0, 0, 0]}),
     "workspace", "below high"),
    ("workspace 1e5", lambda d: d.update(workspace={"low": [-1e5] * 3, "high": [1e5] * 3}),
     "workspace", "inside +-10000 m"),
    ("workspace no high", lambda d: d.update(workspace={"low": [-1] * 3}),
     "workspace.high", "missing"),
    ("workspace unknown key", lambda d: d.update(workspace={"lo": [0] * 3}),
     "workspace", "unknown field"),
    ("margin negative", lambda d: d.update(margin=-0.1), "margin", ">= 0"),
    ("margin 1e6", lambda d: d.update(margin=1e6), "margin", "outside"),
    ("margin text", lambda d: d.update(margin="short"), "margin", "expected a number"),
    ("control_frequency 0", lambda d: d.update(control_frequency=0), "control_frequency",
     "positive integer"),
    ("control_frequency 2.5", lambda d: d.update(control_frequency=2.5), "control_frequency",
     "positive integer"),
    ("control_frequency 5000", lambda d: d.update(control_frequency=5000), "control_frequency",
     "outside"),
    ("time_grid unknown", lambda d: d.update(time_grid="round"), "time_grid", "one of"),
    ("allow_saturation text", lambda d: d.update(allow_saturation="yes"), "allow_saturation",
     "true or false"),
    ("goals for unknown body", lambda d: d.update(goals={"cube": [{"nail": [0, 0, 1]}]}),
     "goals", "unknown body 'cube'"),
    ("goals not a mapping", lambda d: d.update(goals=[1, 2]), "goals", "mapping"),
    ("props not a list", lambda d: d.update(props={"fish": {}}), "props", "list of props"),
    # bodies
    ("body not a mapping", lambda d: d["bodies"].__setitem__(0, "ball"), "bodies[0]", "mapping"),
    ("name missing", lambda d: ball(d).pop("name"), "bodies[0].name", "missing"),
    ("name empty", lambda d: ball(d).update(name=""), "bodies[0].name", "non-empty string"),
    ("name a number", lambda d: ball(d).update(name=3), "bodies[0].name", "non-empty string"),
    ("duplicate body name", lambda d: rod(d).update(name="ball"), "bodies[1].name", "duplicate"),
    ("body named like a prop", lambda d: ball(d).update(name="fish"), "bodies[0].name",
     "duplicate"),
    ("unknown shape", lambda d: ball(d).update(shape="torus"), "bodies[0].shape", "torus"),
    ("rod with one size", lambda d: rod(d).update(size=[0.6]), "bodies[1].size", "2 numbers"),
    ("size negative", lambda d: ball(d).update(size=[-0.05]), "bodies[0].size[0]", "positive"),
    ("size 1e-300", lambda d: ball(d).update(size=[1e-300]), "bodies[0].size[0]", "underflow"),
    ("size 1e5", lambda d: ball(d).update(size=[1e5]), "bodies[0].size[0]", "outside"),
    ("size text", lambda d: ball(d).update(size="small"), "bodies[0].size", "list of numbers"),
    ("mass negative", lambda d: ball(d).update(mass=-2.0), "bodies[0].mass", "positive"),
    ("mass zero", lambda d: ball(d).update(mass=0), "bodies[0].mass", "positive"),
    ("mass 1e-17 (static in PyBullet)", lambda d: ball(d).update(mass=1e-17), "bodies[0].mass",
     "static"),
    ("mass 1e9", lambda d: ball(d).update(mass=1e9), "bodies[0].mass", "outside"),
    ("mass quoted", lambda d: ball(d).update(mass="1.5"), "bodies[0].mass", "remove the quotes"),
    ("mass boolean", lambda d: ball(d).update(mass=True), "bodies[0].mass", "expected a number"),
    ("mass inf", lambda d: ball(d).update(mass=math.inf), "bodies[0].mass", "finite"),
    ("force_limit below weight", lambda d: ball(d).update(force_limit=5.0),
     "bodies[0].force_limit", "against gravity"),
    ("force_limit 1e12", lambda d: ball(d).update(force_limit=1e12), "bodies[0].force_limit",
     "outside"),
    ("torque_limit zero", lambda d: rod(d).update(torque_limit=0), "bodies[1].torque_limit",
     "positive"),
    ("torque_limit NaN", lambda d: rod(d).update(torque_limit=math.nan), "bodies[1].torque_limit",
     "finite"),
    ("position outside workspace", lambda d: ball(d).update(position=[0, 0, 99]),
     "bodies[0].position", "outside the workspace"),
    ("position 2 numbers", lambda d: ball(d).update(position=[0, 0]), "bodies[0].position",
     "3 numbers"),
    ("position 1e300", lambda d: ball(d).update(position=[1e300, 0, 1]), "bodies[0].position",
     "outside the workspace"),
    ("orientation not unit", lambda d: rod(d).update(orientation=[0, 0, 0, 2]),
     "bodies[1].orientation", "bad quaternion"),
    ("orientation zero", lambda d: rod(d).update(orientation=[0, 0, 0, 0]),
     "bodies[1].orientation", "bad quaternion"),
    ("linear_velocity 1e300", lambda d: ball(d).update(linear_velocity=[1e300, 0, 0]),
     "bodies[0].linear_velocity", "100 m/s"),
    ("linear_velocity 95", lambda d: ball(d).update(linear_velocity=[0, 95, 0]),
     "bodies[0].linear_velocity", "outside"),
    ("angular_velocity 1e300", lambda d: rod(d).update(angular_velocity=[0, 0, 1e300]),
     "bodies[1].angular_velocity", "100 rad/s"),
    ("angular_velocity 150", lambda d: rod(d).update(angular_velocity=[150, 0, 0]),
     "bodies[1].angular_velocity", "outside"),
    ("end_velocity 1e300", lambda d: ball(d).update(end_velocity=[1e300, 0, 0]),
     "bodies[0].end_velocity", "outside"),
    ("end_angular_velocity 200", lambda d: rod(d).update(end_angular_velocity=[200, 0, 0]),
     "bodies[1].end_angular_velocity", "outside"),
    ("end_velocity text", lambda d: ball(d).update(end_velocity="stop"),
     "bodies[0].end_velocity", "list of 3"),
    ("color 5 numbers", lambda d: ball(d).update(color=[1, 0, 0, 1, 1]), "bodies[0].color",
     "4 numbers"),
    ("color above 1", lambda d: ball(d).update(color=[2.0, 0, 0]), "bodies[0].color", "RGBA"),
    ("collisions text", lambda d: ball(d).update(collisions="no"), "bodies[0].collisions",
     "true or false"),
    ("unknown body field", lambda d: ball(d).update(colour=[1, 0, 0]), "bodies[0]",
     "unknown field(s) ['colour']"),
    ("goals not a list", lambda d: ball(d).update(goals={"nail": [0, 0, 1]}), "bodies[0].goals",
     "list of goals"),
    ("goals empty", lambda d: rod(d).update(goals=[]), "bodies[1].goals", "empty goal list"),
    ("10001 goals", lambda d: ball(d).update(goals=[{"nail": [0, 0, 1]}] * 10_001),
     "bodies[0].goals", "at most 10000"),
    # goals
    ("goal not a mapping", lambda d: ball(d)["goals"].__setitem__(0, [0.5, 0, 1]),
     "bodies[0].goals[0]", "mapping"),
    ("goal unknown field", lambda d: goal(d, 0).update(when=1.0), "bodies[0].goals[0]",
     "unknown field"),
    ("goal without parts", lambda d: goal(d, 0).pop("nail"), "bodies[0].goals[0]",
     "needs a nail"),
    ("nail NaN", lambda d: goal(d, 2).update(nail=[0, math.nan, 1]), "bodies[0].goals[2].nail",
     "NaN"),
    ("nail outside workspace", lambda d: goal(d, 0).update(nail=[99, 0, 1]),
     "bodies[0].goals[0].nail", "outside the workspace"),
    ("nail 1e300", lambda d: goal(d, 0).update(nail=[1e300, 0, 1]), "bodies[0].goals[0].nail",
     "outside the workspace"),
    ("nail 4 numbers", lambda d: goal(d, 0).update(nail=[0, 0, 1, 0]), "bodies[0].goals[0].nail",
     "3 numbers"),
    ("nail prop unknown", lambda d: goal(d, 2).update(nail={"prop": "shark"}),
     "bodies[0].goals[2].nail.prop", "unknown prop"),
    ("nail mapping bad key", lambda d: goal(d, 2).update(nail={"body": "fish"}),
     "bodies[0].goals[2].nail", "unknown field"),
    ("interception not critical", lambda d: goal(d, 1).update(nail={"prop": "fish"}),
     "bodies[0].goals[1].time", "time-critical"),
    ("point 1e300", lambda d: goal(d, 0).update(point=[1e300, 0, 0]), "bodies[0].goals[0].point",
     "outside"),
    ("point 2e4", lambda d: goal(d, 0).update(point=[0, 2e4, 0]), "bodies[0].goals[0].point",
     "outside"),
    ("time 1e300", lambda d: goal(d, 2).update(time=1e300), "bodies[0].goals[2].time", "outside"),
    ("time 2e5", lambda d: goal(d, 2).update(time=2e5), "bodies[0].goals[2].time", "outside"),
    ("time zero", lambda d: goal(d, 0).update(time=0.0), "bodies[0].goals[0].time",
     "start time 0"),
    ("time negative", lambda d: goal(d, 0).update(time=-1.0), "bodies[0].goals[0].time",
     "start time 0"),
    ("time quoted", lambda d: goal(d, 0).update(time="1e0"), "bodies[0].goals[0].time",
     "remove the quotes"),
    ("time off grid", lambda d: goal(d, 0).update(time=0.51), "bodies[0].goals[0].time",
     "control grid"),
    ("time not increasing", lambda d: goal(d, 2).update(time=0.25), "bodies[0].goals[2].time",
     "not after the previous goal time"),
    ("episode over the tick cap", lambda d: goal(d, 2).update(time=2000.0), "goals",
     "at most 100000"),
    ("critical text", lambda d: goal(d, 0).update(critical="yes"), "bodies[0].goals[0].critical",
     "true or false"),
    ("critical without time", lambda d: goal(d, 1).update(critical=True),
     "bodies[0].goals[1].time", "needs a time"),
    ("weight zero", lambda d: goal(d, 1).update(weight=0.0), "bodies[0].goals[1].weight", "> 0"),
    ("weight negative", lambda d: goal(d, 1).update(weight=-1.0), "bodies[0].goals[1].weight",
     "> 0"),
    ("weight 1e300", lambda d: goal(d, 1).update(weight=1e300), "bodies[0].goals[1].weight",
     "outside"),
    ("last goal untimed", lambda d: goal(d, 2).pop("time"), "bodies[0].goals",
     "last goal must be time-critical"),
    ("orientation and relative_rotation",
     lambda d: goal(d, 0, 1).update(relative_rotation=[0, 0, 1]),
     "bodies[1].goals[0]", "not both"),
    ("goal orientation not unit", lambda d: goal(d, 0, 1).update(orientation=[0, 0, 0, 2]),
     "bodies[1].goals[0].orientation", "bad quaternion"),
    ("relative_rotation 1e300", lambda d: goal(d, 1, 1).update(relative_rotation=[1e300, 0, 0]),
     "bodies[1].goals[1].relative_rotation", "32 turns"),
    ("relative_rotation 1e6", lambda d: goal(d, 1, 1).update(relative_rotation=[0, 1e6, 0]),
     "bodies[1].goals[1].relative_rotation", "outside"),
    ("relative_rotation 4 numbers", lambda d: goal(d, 1, 1).update(relative_rotation=[0, 0, 1, 0]),
     "bodies[1].goals[1].relative_rotation", "3 numbers"),
    ("force demand over the limit", lambda d: goal(d, 0).update(nail=[5, 0, 1]),
     "bodies[0].goals[0]", "above bodies[0].force_limit = 60 N"),
    ("torque demand over the limit",
     lambda d: (rod(d).update(torque_limit=1.0), goal(d, 1, 1).update(relative_rotation=[6, 0, 0])),
     "bodies[1].goals[1]", "above bodies[1].torque_limit = 1 N m"),
    ("spin demand over PyBullet's clamp",
     lambda d: (rod(d).update(torque_limit=1e4),
                goal(d, 1, 1).update(relative_rotation=[0, 0, 100])),
     "bodies[1].goals[1]", "spin of"),
    ("somersault with fewer ticks than courses",
     lambda d: (rod(d).update(torque_limit=1e4),
                goal(d, 1, 1).update(relative_rotation=[0, 0, 150])),
     "bodies[1].goals", "72 courses"),
    ("speed demand over PyBullet's clamp",
     lambda d: (ball(d).update(force_limit=1e5, goals=[{"nail": [60, 0, 1], "time": 0.5}]),
                d.update(workspace={"low": [-100] * 3, "high": [100] * 3})),
     "bodies[0].goals[0]", "speed of"),
    ("plan leaves the workspace",
     lambda d: (ball(d).update(linear_velocity=[0, 0, -9], force_limit=1e3),
                d.update(workspace={"low": [-2, -2, 0.8], "high": [2, 2, 3]})),
     "bodies[0].goals[0]", "leaves the workspace"),
    # point-to-path goals
    ("samples 1e8", lambda d: ball(d)["goals"].insert(1, {
        "path": {"curve": "line", "start": [0.5, 0, 1], "end": [0.5, 0.5, 1]},
        "samples": 100_000_000}), "bodies[0].goals[1].samples", f"at most {MAX_PATH_SAMPLES}"),
    ("samples zero", lambda d: ball(d)["goals"].insert(1, {
        "path": {"curve": "line", "start": [0.5, 0, 1], "end": [0.5, 0.5, 1]}, "samples": 0}),
     "bodies[0].goals[1].samples", "integer >= 1"),
    ("samples 2.5", lambda d: ball(d)["goals"].insert(1, {
        "path": {"curve": "line", "start": [0.5, 0, 1], "end": [0.5, 0.5, 1]}, "samples": 2.5}),
     "bodies[0].goals[1].samples", "integer >= 1"),
    ("unknown curve", lambda d: ball(d)["goals"].insert(1, {
        "path": {"curve": "spiral"}, "samples": 3}), "bodies[0].goals[1].path.curve", "spiral"),
    ("curve missing", lambda d: ball(d)["goals"].insert(1, {
        "path": {"start": [0, 0, 1]}, "samples": 3}), "bodies[0].goals[1].path.curve", "missing"),
    ("curve parameters wrong", lambda d: ball(d)["goals"].insert(1, {
        "path": {"curve": "line", "start": [0, 0, 1]}, "samples": 3}),
     "bodies[0].goals[1].path.end", "missing required field"),
    ("helix 1e9 turns", lambda d: ball(d)["goals"].insert(1, {
        "path": {"curve": "helix", "center": [0.5, 0, 1], "radius": 0.1, "turns": 1e9,
                 "height": 0.1}, "samples": 3}), "bodies[0].goals[1].path.turns", "at most"),
    ("curve radius inf", lambda d: ball(d)["goals"].insert(1, {
        "path": {"curve": "arc", "center": [0.5, 0, 1], "radius": math.inf, "start_angle": 0,
                 "end_angle": 1}, "samples": 3}), "bodies[0].goals[1].path.radius", "finite"),
    ("path goal unknown field", lambda d: ball(d)["goals"].insert(1, {
        "path": {"curve": "line", "start": [0, 0, 1], "end": [1, 0, 1]}, "samples": 3,
        "orientation": [0, 0, 0, 1]}), "bodies[0].goals[1]", "unknown field"),
    # props
    ("prop not a mapping", lambda d: d["props"].__setitem__(0, "fish"), "props[0]", "mapping"),
    ("prop name missing", lambda d: fish(d).pop("name"), "props[0].name", "missing"),
    ("prop unknown field", lambda d: fish(d).update(mass=1.0), "props[0]", "unknown field"),
    ("prop shape unknown", lambda d: fish(d).update(shape="shark"), "props[0].shape", "shark"),
    ("prop size zero", lambda d: fish(d).update(size=[0.0]), "props[0].size[0]", "positive"),
    ("prop color NaN", lambda d: fish(d).update(color=[math.nan, 0, 0]), "props[0].color", "NaN"),
    ("prop velocity 1e300", lambda d: fish(d).update(velocity=[1e300, 0, 0]),
     "props[0].velocity", "outside"),
    ("prop velocity 5e3", lambda d: fish(d).update(velocity=[0, 5e3, 0]), "props[0].velocity",
     "outside"),
    ("prop position 1e300", lambda d: fish(d).update(position=[0, 0, 1e300]),
     "props[0].position", "outside"),
    ("waypoints empty", lambda d: fish(d).update(waypoints=[]), "props[0].waypoints",
     "non-empty list"),
    ("waypoint times not increasing", lambda d: fish(d).update(waypoints=[
        {"time": 1.0, "position": [0, 0, 1]}, {"time": 0.5, "position": [1, 0, 1]}]),
     "props[0].waypoints[1].time", "not after"),
    ("waypoint position NaN", lambda d: fish(d).update(waypoints=[
        {"time": 0.0, "position": [0, math.nan, 1]}]), "props[0].waypoints[0].position", "NaN"),
    ("waypoint time 1e300", lambda d: fish(d).update(waypoints=[
        {"time": 1e300, "position": [0, 0, 1]}]), "props[0].waypoints[0].time", "outside"),
    ("waypoint position 1e300", lambda d: fish(d).update(waypoints=[
        {"time": 0.0, "position": [0, 0, 1e300]}]), "props[0].waypoints[0].position", "outside"),
    ("waypoint unknown key", lambda d: fish(d).update(waypoints=[
        {"t": 0.0, "position": [0, 0, 1]}]), "props[0].waypoints[0]", "unknown field"),
    ("waypoint time missing", lambda d: fish(d).update(waypoints=[{"position": [0, 0, 1]}]),
     "props[0].waypoints[0].time", "missing"),
    ("duplicate prop name", lambda d: d["props"].append({"name": "fish"}), "props[1].name",
     "unique"),
]  # fmt: skip


def test_the_base_scenario_loads():
    s = load(copy.deepcopy(BASE))
    assert [len(b.goals) for b in s.bodies] == [3, 2]


def test_the_table_is_large_and_its_labels_unique():
    assert len(CASES) >= 80
    assert len({c[0] for c in CASES}) == len(CASES)


@pytest.mark.parametrize(("label", "mutate", "field", "fragment"), CASES, ids=[c[0] for c in CASES])
def test_malformed_scenario_names_the_field(label, mutate, field, fragment):
    data = copy.deepcopy(BASE)
    mutate(data)
    with pytest.raises(ScenarioError) as err:
        load(data)
    message = str(err.value)
    assert message.startswith(field), message
    assert fragment in message, message


def test_allow_saturation_opts_out_of_the_force_check():
    data = copy.deepcopy(BASE)
    goal(data, 0).update(nail=[5, 0, 1])
    with pytest.raises(ScenarioError, match="force"):
        load(data)
    data["allow_saturation"] = True
    assert load(data).allow_saturation


def test_every_limit_has_a_reason_and_an_ordered_range():
    for key, (lo, hi, _unit, why) in LIMITS.items():
        assert lo < hi, key
        assert len(why) > 10, key


# ---------------------------------------------------------------- files


def test_directory_named_like_a_scenario(tmp_path):
    folder = tmp_path / "scene.yaml"
    folder.mkdir()
    with pytest.raises(ScenarioError, match="scene.yaml: is a directory"):
        load_scenario(folder)


def test_non_utf8_file_is_named(tmp_path):
    path = tmp_path / "latin.yaml"
    path.write_bytes(b"name: caf\xe9\n")
    with pytest.raises(ScenarioError, match=r"latin.yaml: not UTF-8 text \(byte 9"):
        load_scenario(path)


def test_deep_nesting_is_named(tmp_path):
    path = tmp_path / "deep.yaml"
    path.write_text("bodies: " + "[" * 5000 + "]" * 5000)
    # libyaml stops at its nesting limit; the pure-Python reader runs out of recursion
    with pytest.raises(ScenarioError, match="(?s)deep.yaml: (nested too deeply|.*nesting depth)"):
        load_scenario(path)


def test_broken_yaml_is_named(tmp_path):
    path = tmp_path / "broken.yaml"
    path.write_text("bodies: [\n")
    with pytest.raises(ScenarioError, match="broken.yaml: not valid YAML"):
        load_scenario(path)


def test_yaml_12_exponent_floats_are_numbers(tmp_path):
    data = copy.deepcopy(BASE)
    text = yaml.safe_dump(data).replace("mass: 1.0", "mass: 1e0")
    assert "1e0" in text and yaml.safe_load(text)["bodies"][0]["mass"] == "1e0"  # YAML 1.1
    path = tmp_path / "exp.yaml"
    path.write_text(text)
    assert load_scenario(path).bodies[0].mass == 1.0


def test_relative_rotation_1e300_from_yaml(tmp_path):
    data = copy.deepcopy(BASE)
    goal(data, 1, 1)["relative_rotation"] = [1e300, 0, 0]
    path = tmp_path / "spin.yaml"
    path.write_text(yaml.safe_dump(data))
    with pytest.raises(ScenarioError, match=r"bodies\[1\].goals\[1\].relative_rotation"):
        load_scenario(path)


# ---------------------------------------------------------------- shipped scenes still pass


def test_random_presets_pass_the_plan_check():
    from sgc_env.scenario.demand import check_plan

    rng = np.random.default_rng(7)
    for preset in ("point", "rod"):
        for _ in range(4):
            check_plan(random_scenario(rng, preset))  # raises ScenarioError if infeasible
