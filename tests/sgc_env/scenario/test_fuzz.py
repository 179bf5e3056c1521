"""Fuzzing scenario dictionaries: every draw loads and the expert meets its goals, or the
loader raises ScenarioError. Nothing else is allowed (no other exception, no hang). Raw YAML
text is fuzzed too (a shipped file with hostile edits, and any text): only a ScenarioError or
a scenario may come out.

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
from baselines.evaluation.harness import run_episode  # noqa: E402
from sgc_env.envs import SGCEnv  # noqa: E402
from sgc_env.scenario import ScenarioError, resolve_scenario, scenario_from_dict  # noqa: E402
from sgc_env.scenario.load import builtin_path, scenario_from_yaml  # noqa: E402

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


# ---------------------------------------------------------------- raw YAML text

SEED_TEXT = builtin_path("point_three_goals").read_text(encoding="utf-8")
TOKENS = [
    "nan", ".nan", ".inf", "-.inf", "1e400", "9" * 400, "-" + "9" * 5000, "0x1F", "1_0", "[",
    "]", "{", "}", "null", "~", "true", "yes", "'", '"', "\t", "\x00", "\ufeff", "- ", ": ",
    "? ", "&a [*a]", "*a", "<<: *a", "!!python/object/apply:os.system ['true']", "!!binary x",
    "!!set {a}", "%YAML 1.1\n---\n", "\n---\n", "#", "|\n  x", ">-", "@", "`", "1e0", "-0",
]  # fmt: skip


@st.composite
def yaml_texts(draw) -> str:
    """The shipped point scenario with a few edits: cuts, repeats and hostile tokens."""
    text = SEED_TEXT
    for _ in range(draw(st.integers(1, 4))):
        i = draw(st.integers(0, len(text)))
        j = draw(st.integers(i, min(len(text), i + 12)))
        edit = draw(st.sampled_from(["cut", "token", "text", "repeat"]))
        if edit == "cut":
            text = text[:i] + text[j:]
        elif edit == "token":
            text = text[:i] + draw(st.sampled_from(TOKENS)) + text[j:]
        elif edit == "text":
            text = text[:i] + draw(st.text(max_size=6)) + text[j:]
        else:
            text = text[:i] + text[i:j] * draw(st.integers(2, 50)) + text[j:]
    return text


def load_text(text: str) -> None:
    """Only a ScenarioError (or a scenario) may come out."""
    try:
        scenario_from_yaml(text, "fuzz")
    except ScenarioError:
        pass


@settings(max_examples=150, deadline=timedelta(seconds=5), derandomize=True)
@given(yaml_texts())
def test_edited_yaml_text_loads_or_is_refused(text):
    load_text(text)


@settings(max_examples=60, deadline=timedelta(seconds=5), derandomize=True)
@given(st.text(max_size=60))
def test_any_text_loads_or_is_refused(text):
    load_text(text)


@pytest.mark.parametrize(
    "text",
    [
        "&a [*a]",
        "bodies: &a [*a]",
        "bodies: [{name: b, goals: &g [{nail: *g, time: 1}]}]",
        "bodies: [{name: b, goals: [{nail: [0, 0, " + "9" * 5000 + "], time: 1}]}]",
        "bodies: [{name: " + "9" * 5000 + ", goals: [{nail: [0, 0, 1], time: 1}]}]",
        "control_frequency: " + "9" * 5000 + "\nbodies: [{name: b, goals: [{nail: [0,0,1]}]}]",
        "bodies: [{name: b, shape: [rod], goals: [{nail: [0, 0, 1], time: 1}]}]",
        "{1: 2, null: 3, a: 4}",
    ],
)
def test_hostile_yaml_is_a_scenario_error(text):
    with pytest.raises(ScenarioError):
        scenario_from_yaml(text, "hostile")
