"""Policies x envs through the harness: the comparison loop and its files.

:func:`evaluate_pairs` scores every (env, policy) pair with :func:`~.harness.evaluate`;
:func:`write_pair` writes one pair's ``goals.csv`` and ``summary.json``;
:func:`write_scorecard` the comparison's ``scorecard.json`` and ``scorecard.md``
(:func:`markdown_table`). ``sgc evaluate`` is their command line.
"""

from __future__ import annotations

import json
import math
from collections.abc import Iterator, Mapping, Sequence
from pathlib import Path
from typing import Any

from baselines.evaluation.harness import (
    EvaluationResult,
    evaluate,
    json_ready,
    write_goals_csv,
    write_summary_json,
)

__all__ = [
    "SCORECARD_COLUMNS",
    "evaluate_pairs",
    "expand_envs",
    "format_cell",
    "markdown_table",
    "write_pair",
    "write_scorecard",
]

#: (summary key, column title, format) of the comparison table.
SCORECARD_COLUMNS: tuple[tuple[str, str, str], ...] = (
    ("env_id", "env", "s"),
    ("policy", "policy", "s"),
    ("return_mean", "return", ".1f"),
    ("success_rate", "success", ".2f"),
    ("position_error_max", "pos err max (m)", ".1e"),
    ("orientation_error_max", "ori err max (rad)", ".1e"),
    ("position_closest_offset_abs_max", "closest offset abs max (s)", ".3f"),
    ("sparc_track_mean", "SPARC track", ".2f"),
    ("speed_minima_mean", "speed minima / ep", ".1f"),
    ("goal_speed_ratio_min", "goal speed ratio min", ".3f"),
    ("velocity_jump_max", "vel jump max (m/s)", ".3f"),
    ("acceleration_kink_max", "kink (m/s²)", ".2f"),
    ("angular_acceleration_kink_max", "ang kink (rad/s²)", ".2f"),
    ("force_peak_max", "peak force (N)", ".1f"),
    ("force_sq_integral_mean", "force² ∫ (N² s)", ".0f"),
    ("terminated", "terminated", "d"),
)


def expand_envs(names: Sequence[str]) -> list[str]:
    """Env ids with ``all`` replaced by every SGC id whose observation is a flat Box."""
    import gymnasium as gym

    import sgc_env

    out: list[str] = []
    for name in names:
        if name != "all":
            out.append(name)
            continue
        for env_id in sgc_env.ENV_IDS:
            env = gym.make(env_id)
            flat = isinstance(env.observation_space, gym.spaces.Box)
            env.close()
            if flat:
                out.append(env_id)
    return list(dict.fromkeys(out))


def format_cell(value: Any, fmt: str) -> str:
    """One table cell: ``–`` for a missing or non-finite value."""
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return "–"
    if fmt == "s":
        return str(value)
    return format(value, fmt)


def markdown_table(summaries: Sequence[Mapping[str, Any]]) -> str:
    """The comparison table in GitHub markdown (one row per env and policy)."""
    head = "| " + " | ".join(title for _, title, _ in SCORECARD_COLUMNS) + " |"
    rule = "|" + "|".join("---" for _ in SCORECARD_COLUMNS) + "|"
    body = [
        "| " + " | ".join(format_cell(s.get(k), f) for k, _, f in SCORECARD_COLUMNS) + " |"
        for s in summaries
    ]
    return "\n".join([head, rule, *body]) + "\n"


def evaluate_pairs(
    specs: Sequence[str], labels: Sequence[str], env_ids: Sequence[str], **harness: Any
) -> Iterator[tuple[str, str, EvaluationResult]]:
    """``(env_id, label, result)`` of every env and policy, env by env; ``harness``: the
    keyword arguments of :func:`~.harness.evaluate` (episodes, seed, tolerances ...)."""
    for env_id in env_ids:
        for spec, label in zip(specs, labels, strict=True):
            yield env_id, label, evaluate(spec, env_id, label=label, **harness)


def write_pair(result: EvaluationResult, folder: Path) -> None:
    """``goals.csv`` and ``summary.json`` of one pair."""
    write_goals_csv(result.rows, folder / "goals.csv")
    write_summary_json(result.summary, folder / "summary.json")


def write_scorecard(summaries: Sequence[Mapping[str, Any]], folder: Path) -> None:
    """``scorecard.json`` and ``scorecard.md`` of a comparison."""
    (folder / "scorecard.json").write_text(
        json.dumps(json_ready(list(summaries)), indent=2, allow_nan=False) + "\n"
    )
    (folder / "scorecard.md").write_text(markdown_table(summaries))
