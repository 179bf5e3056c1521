"""Scenarios: the data model, its fields and limits, parsing, validation, resolution, the
plan-demand check, loading and the built-in YAML files (``builtin/``).

A scenario is plain frozen data. :func:`resolve_scenario` turns a user scenario into the form
the environment runs (every goal timed on the control grid, prop nails computed, the plan the
expert flies checked against the limits); :func:`load_scenario` reads one from YAML first.
Modules, bottom up: ``model`` <- ``fields`` <- ``curves`` <- ``parse``; ``validate`` <-
``demand`` <- ``resolve`` <- ``load``; ``orientation_courses`` (an orientation track's
courses, memoised for the env's tracks and the three-rod course bound; not imported here).
"""

from __future__ import annotations

from sgc_env.scenario.curves import parametric_curve, path_goals
from sgc_env.scenario.fields import LIMITS, MAX_PATH_SAMPLES, SHAPES
from sgc_env.scenario.load import builtin_scenarios, load_scenario
from sgc_env.scenario.model import Body, Goal, Prop, Scenario, ScenarioError
from sgc_env.scenario.parse import scenario_from_dict
from sgc_env.scenario.resolve import resolve_scenario

__all__ = [
    "LIMITS",
    "MAX_PATH_SAMPLES",
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
