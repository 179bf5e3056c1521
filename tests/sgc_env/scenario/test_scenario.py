"""Scenario model: loading, routing, point-to-path goals, props, and validation messages."""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest
import yaml

from sgc_env.scenario import (
    Body,
    Goal,
    Prop,
    Scenario,
    ScenarioError,
    builtin_scenarios,
    load_scenario,
    parametric_curve,
    path_goals,
    resolve_scenario,
    scenario_from_dict,
)
from sgc_env.scenes import RandomScenarioConfig, random_scenario

BASE = {
    "name": "t",
    "bodies": [
        {
            "name": "ball",
            "shape": "sphere",
            "size": [0.05],
            "mass": 1.0,
            "position": [0, 0, 1],
            "goals": [
                {"nail": [1, 0, 1], "time": 0.5},
                {"nail": [1, 1, 1]},
                {"nail": [0, 1, 1], "time": 1.5},
            ],
        },
        {
            "name": "rod1",
            "shape": "rod",
            "size": [0.6, 0.03],
            "mass": 2.0,
            "position": [0, 0, 2],
            "goals": [{"orientation": [0, 0, 0, 1], "time": 1.0}],
        },
    ],
}


def load(data: dict) -> Scenario:
    return resolve_scenario(scenario_from_dict(data))


def mutated(fn) -> dict:
    data = copy.deepcopy(BASE)
    fn(data)
    return data


def test_builtins_load_and_times_on_grid():
    names = builtin_scenarios()
    assert {"point_three_goals", "rod_basic", "three_rods", "intercept"} <= set(names)
    for name in names:
        s = load_scenario(name)
        assert s.resolved
        for b in s.bodies:
            times = [g.time for g in b.goals]
            assert all(t2 > t1 for t1, t2 in zip(times, times[1:], strict=False))
            for t in times:
                assert abs(t * s.control_frequency - round(t * s.control_frequency)) < 1e-9


def test_routing_fills_noncritical_times_by_distance():
    s = load(BASE)
    g = s.bodies[0].goals
    # courses 2 and 3 have equal length and weight: the middle goal sits half way in time.
    assert g[1].time == pytest.approx(1.0)
    assert g[1].critical is False and g[0].critical is True


def test_resolve_is_idempotent():
    s = load(BASE)
    assert resolve_scenario(s) == s


def test_yaml_round_trip(tmp_path):
    path = tmp_path / "s.yaml"
    path.write_text(yaml.safe_dump(BASE))
    assert load_scenario(path) == load(BASE)


def test_path_goals_times_follow_arc_length():
    arc = parametric_curve("arc", center=[0, 0, 1], radius=1.0, start_angle=0.0, end_angle=math.pi)
    goals = path_goals(arc, 6, time=1.2)
    body = Body("b", position=(1.0, 0.0, 1.0), goals=goals)
    # Only the timing matters here: the limits stay at their defaults, so saturation is allowed.
    s = resolve_scenario(Scenario(bodies=(body,), allow_saturation=True))
    times = np.array([g.time for g in s.bodies[0].goals])
    np.testing.assert_allclose(np.diff(np.concatenate(([0], times))), 0.2, atol=1e-12)


def test_named_curves_from_yaml():
    data = mutated(
        lambda d: d["bodies"][0]["goals"].insert(
            1,
            {"path": {"curve": "helix", "center": [1, 0.5, 1], "radius": 0.5, "turns": 1,
                      "height": 0.3, "start_angle": -1.5707963}, "samples": 4},
        )
    )  # fmt: skip
    data["allow_saturation"] = True  # a full helix turn in 0.5 s needs more than 50 N
    s = load(data)
    assert len(s.bodies[0].goals) == 7


def test_intercept_nail_is_prop_position_at_goal_time():
    s = load_scenario("intercept")
    fish = s.props[0]
    last = s.bodies[0].goals[-1]
    np.testing.assert_allclose(last.nail, fish.position_at(last.time))


def test_snap_mode_rounds_off_grid_times():
    data = mutated(lambda d: d["bodies"][0]["goals"][0].update(time=0.501))
    data["time_grid"] = "snap"
    assert load(data).bodies[0].goals[0].time == 0.5


def test_random_scenarios_are_valid_and_on_grid():
    rng = np.random.default_rng(3)
    cfg = RandomScenarioConfig(n_goals=(2, 6), orientation=True, shape="rod", size=(0.6, 0.03))
    for _ in range(20):
        s = random_scenario(rng, cfg)
        assert s.resolved
        for g in s.bodies[0].goals:
            assert abs(g.time * 60 - round(g.time * 60)) < 1e-9


BAD_INPUTS = [
    ("negative mass", lambda d: d["bodies"][1].update(mass=-2.0),
     "bodies[1].mass: expected a positive number, got -2.0"),
    ("nail NaN", lambda d: d["bodies"][0]["goals"][2].update(nail=[0, float("nan"), 1]),
     "bodies[0].goals[2].nail: contains NaN"),
    ("unknown body", lambda d: d.update(goals={"rod9": [{"nail": [0, 0, 1], "time": 2.0}]}),
     "goals refer to unknown body 'rod9'"),
    ("non-increasing", lambda d: d["bodies"][0]["goals"][2].update(time=0.25),
     "bodies[0].goals[2].time: 0.25 is not after the previous goal time 0.5"),
    ("off grid", lambda d: d["bodies"][0]["goals"][0].update(time=0.51),
     "bodies[0].goals[0].time: 0.51 is not on the control grid"),
    ("zero weight", lambda d: d["bodies"][0]["goals"][1].update(weight=0.0),
     "bodies[0].goals[1].weight: routing weight must be > 0"),
    ("empty goals", lambda d: d["bodies"][1].update(goals=[]),
     "bodies[1].goals: empty goal list"),
    ("unknown shape", lambda d: d["bodies"][0].update(shape="torus"),
     "bodies[0].shape: unknown shape 'torus'"),
    ("bad quaternion", lambda d: d["bodies"][1]["goals"][0].update(orientation=[0, 0, 0, 2]),
     "bodies[1].goals[0].orientation: bad quaternion"),
    ("missing name", lambda d: d["bodies"][0].pop("name"),
     "bodies[0].name: missing required field"),
    ("wrong type", lambda d: d["bodies"][0].update(position="origin"),
     "bodies[0].position: expected a list of 3 numbers"),
    ("goal without parts", lambda d: d["bodies"][0]["goals"][0].pop("nail"),
     "bodies[0].goals[0]: a goal needs a nail"),
    ("wrong size", lambda d: d["bodies"][1].update(size=[0.6]),
     "bodies[1].size: a rod needs 2 numbers"),
    ("unknown field", lambda d: d["bodies"][0].update(colour=[1, 0, 0]),
     "bodies[0]: unknown field(s) ['colour']"),
    ("last goal untimed", lambda d: d["bodies"][0]["goals"][2].pop("time"),
     "the last goal must be time-critical"),
    ("unknown prop", lambda d: d["bodies"][0]["goals"][2].update(nail={"prop": "fish"}),
     "bodies[0].goals[2].nail.prop: refers to unknown prop 'fish'"),
    ("nail outside workspace", lambda d: d["bodies"][0]["goals"][0].update(nail=[99, 0, 1]),
     "bodies[0].goals[0].nail: (99.0, 0.0, 1.0) lies outside the workspace"),
    ("weak force limit", lambda d: d["bodies"][0].update(force_limit=5.0),
     "bodies[0].force_limit: 5.0 N cannot hold the body against gravity"),
    ("bad time grid", lambda d: d.update(time_grid="round"),
     "time_grid: expected one of ('reject', 'snap')"),
    ("bad end rule", lambda d: d.update(end_velocity_rule="spline"),
     "end_velocity_rule: expected one of ('tangent', 'paper'), got 'spline'"),
    ("no bodies", lambda d: d.update(bodies=[]),
     "bodies: expected a non-empty list of bodies"),
]  # fmt: skip


@pytest.mark.parametrize(("label", "mutate", "message"), BAD_INPUTS, ids=[b[0] for b in BAD_INPUTS])
def test_bad_input_is_rejected_with_field_path(label, mutate, message):
    with pytest.raises(ScenarioError) as err:
        load(mutated(mutate))
    assert message in str(err.value), str(err.value)


def test_off_grid_message_names_nearest_ticks():
    with pytest.raises(ScenarioError, match=r"nearest ticks are 0\.5 and 0\.5166"):
        load(mutated(lambda d: d["bodies"][0]["goals"][0].update(time=0.51)))


def test_code_built_scenario_is_validated_too():
    body = Body("b", mass=1.0, goals=(Goal(nail=(1.0, 0.0, 0.0), time=0.5),))
    prop = Prop("b", position=(0.0, 0.0, 0.0))
    with pytest.raises(ScenarioError, match="duplicate name .b."):
        resolve_scenario(Scenario(bodies=(body,), props=(prop,)))


def test_unknown_builtin_lists_choices():
    with pytest.raises(ScenarioError, match="built-ins"):
        load_scenario("no_such_scene")


@pytest.mark.parametrize("preset", ["point", "rod"])
def test_random_limits_cover_the_analytic_plan(preset):
    pytest.importorskip("sgc_env.paper.plan")
    from sgc_env.scenario.demand import demand_bounds

    rng = np.random.default_rng(123)
    for _ in range(12):
        s = random_scenario(rng, preset)
        body = s.bodies[0]
        ((force, torque),) = demand_bounds(s, samples=100)
        assert force < body.force_limit
        if body.has_orientation_track:
            assert torque < body.torque_limit
