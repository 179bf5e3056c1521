"""Reading a finished run's ``result.json`` or ``failed.json`` back, checked before the report.

A benchmark folder may come from elsewhere (a colleague's runs, a copied cluster folder), and
``--report-only`` builds the leaderboard from whatever is there. Each record is read within
the caps (:mod:`sgc_env.scenario.bounded`) and must be the run the grid expects in that folder
with the fields the report reads, of the right types; anything else is one ``ValueError``
naming the file and the field, never a ``KeyError`` deep inside the aggregation.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from baselines.benchmark.grid import RunSpec
from sgc_env.scenario.bounded import escaped, load_json, read_bounded

__all__ = ["read_record"]

_NUMBERS = ("timesteps", "wall_time_s", "steps_per_s")
"""Fields of a finished run the report reads as finite numbers (``train_*``: number or null)."""
_OPTIONAL_NUMBERS = ("train_time_s", "train_cpu_s")


def _finite(value: Any) -> bool:
    return not isinstance(value, bool) and isinstance(value, int | float) and math.isfinite(value)


def _check_finished(record: Mapping[str, Any], where: str) -> None:
    for key in _NUMBERS:
        if not _finite(record.get(key)):
            raise ValueError(f"{where}: {key} must be a finite number, got "
                             f"{escaped(repr(record.get(key)), 80)}")  # fmt: skip
    for key in _OPTIONAL_NUMBERS:
        if record.get(key) is not None and not _finite(record[key]):
            raise ValueError(f"{where}: {key} must be a finite number or null")
    if not isinstance(record.get("command"), str):
        raise ValueError(f"{where}: command must be a string")
    scores = record.get("scores")
    if not isinstance(scores, Mapping) or not all(isinstance(scores.get(m), Mapping)
                                                  for m in ("final", "best")):  # fmt: skip
        raise ValueError(f"{where}: scores must map final and best to metrics")
    for model in ("final", "best"):
        for key, value in scores[model].items():
            if value is not None and not isinstance(value, int | float | str | list):
                raise ValueError(f"{where}: scores.{model}.{escaped(key, 80)} is not a value")
    curve = record.get("curve", [])
    if not isinstance(curve, list) or not all(isinstance(e, Mapping) for e in curve):
        raise ValueError(f"{where}: curve must be a list of evaluations")
    for i, point in enumerate(curve):
        for axis in ("timesteps", "train_time_s", "success_rate"):
            if point.get(axis) is not None and not _finite(point[axis]):
                raise ValueError(f"{where}: curve[{i}].{axis} must be a finite number")


def _check_spec(shown: Any, spec: RunSpec, where: str) -> None:
    """The recorded spec is this folder's run, with the fields the report reads well typed."""
    recipe = shown.get("recipe") if isinstance(shown, Mapping) else None
    if not (isinstance(recipe, Mapping) and shown.get("env_id") == spec.env_id
            and shown.get("seed") == spec.seed
            and recipe.get("name") == spec.recipe.name):  # fmt: skip
        raise ValueError(f"{where}: its spec is not the run {spec.run_id} this folder holds "
                         "(moved from another benchmark, or edited)")  # fmt: skip
    budget = recipe.get("time_budget_s")
    typed = (isinstance(recipe.get("algo"), str) and isinstance(recipe.get("demonstrations"), bool)
             and all(isinstance(shown.get(k), int) and not isinstance(shown.get(k), bool)
                     for k in ("eval_episodes", "test_seed"))
             and (budget is None or _finite(budget)))  # fmt: skip
    if not typed:
        raise ValueError(f"{where}: spec: recipe.algo, recipe.demonstrations, eval_episodes, "
                         "test_seed or recipe.time_budget_s missing or of the wrong type")


def read_record(path: Path, spec: RunSpec, finished: bool) -> dict[str, Any]:
    """The record at ``path`` (``result.json`` when ``finished``, else ``failed.json``) of the
    run ``spec``, or a ValueError naming the file and the field."""
    where = f"benchmark result {escaped(path)}"
    record = load_json(read_bounded(path, "benchmark result"), where)
    if not isinstance(record, dict):
        raise ValueError(f"{where}: expected a JSON object, got {type(record).__name__}")
    _check_spec(record.get("spec"), spec, where)
    if finished:
        _check_finished(record, where)
    elif not isinstance(record.get("error", ""), str):
        raise ValueError(f"{where}: error must be a string")
    return record
