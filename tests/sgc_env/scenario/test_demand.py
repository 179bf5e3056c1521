"""Validation checks the plan the expert flies: the scenario's ``end_velocity_rule``.

The expert flies the paper's k rules when a scenario says ``end_velocity_rule: paper``; the
plan check must then measure that plan, not the tangent one (issue 20: a paper-rule three-rod
scene was checked against the tangent plan's 88 N while the flight peaked at 112 N).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from baselines.controllers.expert import SGCExpert
from sgc_env.envs import SGCEnv
from sgc_env.paper.end_rules import END_RULES
from sgc_env.scenario import ScenarioError, resolve_scenario, scenario_from_dict
from sgc_env.scenario.demand import body_demands
from sgc_env.scenario.load import builtin_data


def _scene(rule: str, force_limit: float = 60.0):
    data = builtin_data("point_three_goals")
    data["end_velocity_rule"] = rule
    data["bodies"][0]["force_limit"] = force_limit
    return resolve_scenario(scenario_from_dict(data))


def _flown_peak_force(scenario) -> float:
    """Largest force the expert (which follows the scenario's rule) applies flying
    ``scenario`` in PyBullet."""
    env = SGCEnv(scenario=scenario)
    expert = SGCExpert(env)
    assert expert.model.end_rule == scenario.end_velocity_rule
    obs, _ = env.reset(seed=0)
    peak, done = 0.0, False
    while not done:
        action, _ = expert.predict(obs, deterministic=True)
        obs, _, terminated, truncated, info = env.step(action)
        peak = max(peak, float(np.linalg.norm(info["force"], axis=1).max()))
        done = terminated or truncated
    env.close()
    return peak


@pytest.mark.parametrize("rule", END_RULES)
def test_the_checked_peak_is_the_flown_peak_of_the_rule(rule):
    """The check bounds the flight of its own rule closely (the per-period average of the
    plan sits a little above the expert's deadbeat force), and misses the other rule's."""
    checked = {r: body_demands(_scene(r))[0].force for r in END_RULES}
    flown = _flown_peak_force(_scene(rule))
    assert 0.8 * checked[rule] <= flown <= checked[rule]
    for other in set(END_RULES) - {rule}:
        assert not 0.8 * checked[other] <= flown <= checked[other]


def test_the_rules_ask_for_different_peaks():
    """Otherwise the test above could not tell which plan was checked."""
    tangent, paper = (body_demands(_scene(rule))[0].force for rule in ("tangent", "paper"))
    assert paper > 1.3 * tangent


def test_a_limit_between_the_rules_rejects_only_the_paper_rule():
    tangent, paper = (body_demands(_scene(rule))[0].force for rule in ("tangent", "paper"))
    limit = 0.5 * (tangent + paper)
    assert _scene("tangent", limit).end_velocity_rule == "tangent"  # loads
    where = r"bodies\[0\]\.goals\[\d\]"
    with pytest.raises(ScenarioError, match=rf"{where}: .*peak force of {paper:.4g}"):
        _scene("paper", limit)


def test_a_resolved_scenario_changing_its_rule_is_checked_again():
    scenario = _scene("tangent", 25.0)
    with pytest.raises(ScenarioError, match="peak force"):
        resolve_scenario(replace(scenario, end_velocity_rule="paper"))
