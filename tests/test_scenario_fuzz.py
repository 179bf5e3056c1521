"""Fuzzing scenario dictionaries: every draw loads and the expert meets its goals, or the
loader raises ScenarioError. Nothing else is allowed (no other exception, no hang).

Draws are one-body scenes (two bodies could collide, which no validation can rule out) built
from mostly sensible values with hostile ones mixed in: huge, tiny, NaN, inf, wrong types.
Each draw is bounded by hypothesis' ``deadline``; the default run stays under a minute on a
loaded machine, the ``slow`` one draws ten times as many.
"""

from __future__ import annotations

import math
from datetime import timedelta

import pytest

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from baselines import SGCExpert  # noqa: E402
from baselines.evaluation import run_episode  # noqa: E402
from sgc_env.envs import SGCEnv  # noqa: E402
from sgc_env.scenario import ScenarioError, resolve_scenario, scenario_from_dict  # noqa: E402

HOSTILE = st.sampled_from(
    [0.0, -1.0, 1e-300, 1e-17, 1e6, 1e300, -1e300, math.nan, math.inf, -math.inf, "1e0", None]
)
JUNK = st.one_of(HOSTILE, st.text(max_size=3), st.booleans(), st.lists(st.integers(), max_size=2))


def sometimes(strategy, junk=JUNK):
    """Mostly ``strategy``, one time in twenty something hostile."""
    return st.integers(0, 19).flatmap(lambda k: junk if k == 7 else strategy)


def vec(lo: float, hi: float, z: float = 0.0):
    """A 3-vector in [lo, hi] (z shifted by ``z``), sometimes hostile."""
    xyz = st.tuples(st.floats(lo, hi), st.floats(lo, hi), st.floats(lo + z, hi + z))
    return sometimes(xyz.map(list))


@st.composite
def scenarios(draw) -> dict:
    shape = draw(st.sampled_from(["sphere", "rod", "box"]))
    size = {"sphere": [0.05], "rod": [0.6, 0.03], "box": [0.1, 0.05, 0.05]}[shape]
    body: dict = {
        "name": "b",
        "shape": shape,
        "size": draw(sometimes(st.just(size))),
        "mass": draw(sometimes(st.floats(0.1, 5.0))),
        "position": [0.0, 0.0, 1.0],
        "force_limit": draw(sometimes(st.floats(20.0, 400.0))),
        "torque_limit": draw(sometimes(st.floats(0.5, 20.0))),
    }
    if draw(st.booleans()):
        body["linear_velocity"] = draw(vec(-2.0, 2.0))
    if draw(st.booleans()):
        body["angular_velocity"] = draw(vec(-3.0, 3.0))
    if draw(st.booleans()):
        body["end_velocity"] = draw(vec(-1.0, 1.0))
    goals = []
    tick = 0
    for _ in range(draw(st.integers(1, 3))):
        tick += draw(st.integers(12, 60))
        goal: dict = {"time": draw(sometimes(st.just(tick / 60.0)))}
        if draw(st.booleans()) or shape == "sphere":
            goal["nail"] = draw(vec(-1.5, 1.5, z=1.0))
        if shape != "sphere" or draw(st.booleans()):
            goal["relative_rotation"] = draw(vec(-3.0, 3.0))
        if draw(st.integers(0, 9)) == 5:
            goal["weight"] = draw(JUNK)
        goals.append(goal)
    body["goals"] = goals
    data = {"name": "fuzz", "bodies": [body], "workspace": {"low": [-5] * 3, "high": [5] * 3}}
    if draw(st.integers(0, 9)) == 5:
        data["gravity"] = draw(vec(-20.0, 20.0))
    if draw(st.integers(0, 9)) == 5:
        data["margin"] = draw(JUNK)
    return data


def check(data: dict) -> None:
    try:
        scenario = resolve_scenario(scenario_from_dict(data))
    except ScenarioError:
        return
    env = SGCEnv(scenario)
    try:
        record = run_episode(SGCExpert(env), env, seed=0)
    finally:
        env.close()
    card = record.card
    assert not record.terminated, data
    assert card["goals_met"] == card["n_goals"], (data, card["goals_met"], card["n_goals"])


FAST = settings(
    max_examples=25,
    deadline=timedelta(seconds=20),
    derandomize=True,
    suppress_health_check=[HealthCheck.too_slow],
)


@FAST
@given(scenarios())
def test_fuzzed_scenarios_load_and_are_met_or_are_rejected(data):
    check(data)


@pytest.mark.slow
@settings(FAST, max_examples=300)
@given(scenarios())
def test_fuzzed_scenarios_many(data):
    check(data)
