"""One evaluation harness for every policy: seeded episodes, per-goal rows, a scorecard.

``evaluate(policy, env_id, episodes, seed)`` runs episode k with ``reset(seed=seed + k)``,
keeps the reset info and every step's info, scores each episode with
:func:`sgc_env.metrics.score_episode` against :func:`goals_from_scenario` of the scenario the
episode actually ran (:mod:`baselines.evaluation.episodes`), and aggregates. ``num_envs`` > 1 runs
the episodes on that many sub-envs of the batched env at once, with the same episodes. It imports
neither torch nor SB3 (only a model path spec does, through
:func:`baselines.policies.make_policy`), so a training callback can call it with the model
object itself on held-out seeds.
"""

from __future__ import annotations

import csv
import json
import math
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TypedDict, cast

import gymnasium as gym
import numpy as np

import sgc_env
from baselines.evaluation.episodes import EpisodeRecord, run_episode, run_episodes_batched
from baselines.policies import Policy, make_policy, needs_planner_view, policy_label
from sgc_env.envs.vector.vector_env import make_vec
from sgc_env.metrics import Tolerances

__all__ = [
    "GOAL_COLUMNS",
    "SUMMARY_KEYS",
    "GoalRow",
    "Scorecard",
    "EpisodeRecord",
    "EvaluationResult",
    "evaluate",
    "goal_rows",
    "json_ready",
    "run_episode",
    "summarize",
    "write_goals_csv",
    "write_summary_json",
]


class GoalRow(TypedDict):
    """One goal of one episode in the per-goal table (``goals.csv``); None where n/a."""

    env_id: str
    policy: str
    episode: int
    seed: int
    body: int
    goal: int
    time: float
    position_error: float | None
    orientation_error: float | None
    closest_approach_offset: float
    entry_offset: float
    position_closest_offset: float | None
    orientation_closest_offset: float | None
    position_entry_offset: float | None
    orientation_entry_offset: float | None
    closest_distance: float | None
    closest_angle: float | None
    speed: float | None
    goal_speed_ratio: float | None
    velocity_jump: float | None
    angular_velocity_jump: float | None
    success: bool


class Scorecard(TypedDict):
    """The summary of one policy on one env, grouped as in docs/evaluation.md."""

    env_id: str
    policy: str
    episodes: int
    seed: int
    steps: int
    wall_time_s: float
    return_mean: float
    terminated: int
    n_goals: int
    goals_met: int
    goals_after_end: int
    success_rate: float
    position_error_max: float
    position_error_mean: float
    orientation_error_max: float
    orientation_error_mean: float
    position_closest_offset_abs_max: float
    orientation_closest_offset_abs_max: float
    position_entry_offset_abs_max: float
    orientation_entry_offset_abs_max: float
    sparc_mean: float
    sparc_track_mean: float
    ldlj_mean: float
    ldlj_track_mean: float
    angular_sparc_mean: float
    angular_ldlj_mean: float
    angular_ldlj_track_mean: float
    velocity_jump_max: float
    angular_velocity_jump_max: float
    acceleration_peak_max: float
    acceleration_kink_max: float
    angular_acceleration_peak_max: float
    angular_acceleration_kink_max: float
    speed_minima_mean: float
    goal_speed_ratio_min: float
    rotation_ratio_max: float
    rotation_excess_mean: float
    force_sq_integral_mean: float
    torque_sq_integral_mean: float
    force_peak_max: float
    torque_peak_max: float


GOAL_COLUMNS: tuple[str, ...] = tuple(GoalRow.__annotations__)
"""Columns of ``goals.csv``, in order: the keys of :class:`GoalRow`."""

SUMMARY_KEYS: tuple[str, ...] = tuple(Scorecard.__annotations__)
"""Keys of the summary scorecard, in order: the keys of :class:`Scorecard`."""

PolicyLike = Policy


@dataclass
class EvaluationResult:
    """All episodes of one policy on one env: per-goal ``rows`` and the ``summary`` card."""

    env_id: str
    policy: str
    seed: int
    episodes: list[EpisodeRecord]
    rows: list[GoalRow] = field(default_factory=list)
    summary: Scorecard = field(default_factory=dict)  # type: ignore[assignment]


def _finite(values: Iterable[Any]) -> np.ndarray:
    arr = np.array([np.nan if v is None else float(v) for v in values], dtype=float)
    return arr[np.isfinite(arr)]


def _max(values: Iterable[Any]) -> float:
    arr = _finite(values)
    return float(arr.max()) if arr.size else math.nan


def _min(values: Iterable[Any]) -> float:
    arr = _finite(values)
    return float(arr.min()) if arr.size else math.nan


def _mean(values: Iterable[Any]) -> float:
    arr = _finite(values)
    return float(arr.mean()) if arr.size else math.nan


def _first_finite(*values: Any) -> float:
    for v in values:
        if v is not None and math.isfinite(v):
            return float(v)
    return math.nan


def goal_rows(record: EpisodeRecord, env_id: str, policy: str) -> list[GoalRow]:
    """One row per goal of every body (columns :data:`GOAL_COLUMNS`; None where n/a).

    A goal with a nail and an orientation is one row; ``closest_approach_offset`` and
    ``entry_offset`` (s, signed, positive = late) are the position track's where the goal
    has a nail, else the orientation track's.
    """
    rows: list[GoalRow] = []
    for b, (body_goals, card) in enumerate(zip(record.goals, record.card["bodies"], strict=True)):
        if card is None:
            continue
        pos = iter(card["position_goals"])
        ori = iter(card["orientation_goals"])
        for j, goal in enumerate(body_goals):
            p = next(pos) if goal.nail is not None else {}
            o = next(ori) if goal.orientation is not None else {}
            rows.append(
                {
                    "env_id": env_id,
                    "policy": policy,
                    "episode": record.episode,
                    "seed": record.seed,
                    "body": b,
                    "goal": j,
                    "time": goal.time,
                    "position_error": p.get("position_error"),
                    "orientation_error": o.get("orientation_error"),
                    "closest_approach_offset": _first_finite(
                        p.get("closest_offset"), o.get("closest_offset")
                    ),
                    "entry_offset": _first_finite(p.get("entry_offset"), o.get("entry_offset")),
                    "position_closest_offset": p.get("closest_offset"),
                    "orientation_closest_offset": o.get("closest_offset"),
                    "position_entry_offset": p.get("entry_offset"),
                    "orientation_entry_offset": o.get("entry_offset"),
                    "closest_distance": p.get("closest_distance"),
                    "closest_angle": o.get("closest_angle"),
                    "speed": p.get("speed"),
                    "goal_speed_ratio": p.get("goal_speed_ratio"),
                    "velocity_jump": p.get("velocity_jump"),
                    "angular_velocity_jump": o.get("angular_velocity_jump"),
                    "success": bool(card["met"][j]),
                }
            )
    return rows


def summarize(
    records: Sequence[EpisodeRecord], rows: Sequence[Mapping[str, Any]]
) -> dict[str, Any]:
    """Scorecard over episodes: maxima of errors, offsets and jumps, means of the rest."""
    cards = [r.card for r in records]
    bodies = [b for c in cards for b in c["bodies"] if b is not None]
    n_goals = sum(c["n_goals"] for c in cards)
    met = sum(c["goals_met"] for c in cards)

    def column(key: str) -> list[Any]:
        return [row[key] for row in rows]

    return {
        "episodes": len(records),
        "steps": sum(r.steps for r in records),
        "wall_time_s": sum(r.wall_time_s for r in records),
        "return_mean": _mean(r.episode_return for r in records),
        "terminated": sum(r.terminated for r in records),
        "n_goals": n_goals,
        "goals_met": met,
        "goals_after_end": sum(c["goals_after_end"] for c in cards),
        "success_rate": met / n_goals if n_goals else math.nan,
        "position_error_max": _max(column("position_error")),
        "position_error_mean": _mean(column("position_error")),
        "orientation_error_max": _max(column("orientation_error")),
        "orientation_error_mean": _mean(column("orientation_error")),
        "position_closest_offset_abs_max": _max(
            abs(v) for v in _finite(column("position_closest_offset"))
        ),
        "orientation_closest_offset_abs_max": _max(
            abs(v) for v in _finite(column("orientation_closest_offset"))
        ),
        "position_entry_offset_abs_max": _max(
            abs(v) for v in _finite(column("position_entry_offset"))
        ),
        "orientation_entry_offset_abs_max": _max(
            abs(v) for v in _finite(column("orientation_entry_offset"))
        ),
        "sparc_mean": _mean(c["sparc_mean"] for c in cards),
        "sparc_track_mean": _mean(c["sparc_track_mean"] for c in cards),
        "ldlj_mean": _mean(c["ldlj_mean"] for c in cards),
        "ldlj_track_mean": _mean(c["ldlj_track_mean"] for c in cards),
        "angular_sparc_mean": _mean(c["angular_sparc_mean"] for c in cards),
        "angular_ldlj_mean": _mean(c["angular_ldlj_mean"] for c in cards),
        "angular_ldlj_track_mean": _mean(c["angular_ldlj_track_mean"] for c in cards),
        "velocity_jump_max": _max(c["velocity_jump_max"] for c in cards),
        "angular_velocity_jump_max": _max(c["angular_velocity_jump_max"] for c in cards),
        **{
            f"{key}_max": _max(c[key] for c in cards)
            for key in ("acceleration_peak", "acceleration_kink", "angular_acceleration_peak",
                        "angular_acceleration_kink")
        },  # fmt: skip
        "speed_minima_mean": _mean(c["speed_minima_total"] for c in cards),
        "goal_speed_ratio_min": _min(b["goal_speed_ratio_min"] for b in bodies),
        "rotation_ratio_max": _max(c["rotation_ratio_max"] for c in cards),
        "rotation_excess_mean": _mean(c["rotation_excess_total"] for c in cards),
        "force_sq_integral_mean": _mean(c["force_sq_integral"] for c in cards),
        "torque_sq_integral_mean": _mean(c["torque_sq_integral"] for c in cards),
        "force_peak_max": _max(c["force_peak"] for c in cards),
        "torque_peak_max": _max(c["torque_peak"] for c in cards),
    }


def _resolve_policy(
    policy: PolicyLike | str | Callable[[gym.Env], PolicyLike], env: gym.Env, seed: int
) -> tuple[PolicyLike, str]:
    if isinstance(policy, str):
        return make_policy(policy, env, seed=seed), policy_label(policy)
    if isinstance(policy, type) or (callable(policy) and not hasattr(policy, "predict")):
        built = cast(Callable[[Any], Policy], policy)(env)
        return built, type(built).__name__
    if not hasattr(policy, "predict"):
        raise ValueError(
            f"policy must be a spec string, an object with .predict or a factory of one, "
            f"got {type(policy).__name__}"
        )
    return cast(PolicyLike, policy), type(policy).__name__


def evaluate(
    policy: PolicyLike | str | Callable[[gym.Env], PolicyLike],
    env_id: str,
    episodes: int,
    seed: int,
    env_kwargs: Mapping[str, Any] | None = None,
    tolerances: Tolerances | None = None,
    *,
    label: str | None = None,
    keep_infos: int = 1,
    num_envs: int = 1,
) -> EvaluationResult:
    """Run ``episodes`` seeded episodes (episode k: ``reset(seed=seed + k)``) and score them.

    ``policy``: a spec for :func:`make_policy` (``"expert"``, ``"random"``, a model path...),
    an object with an SB3-style ``predict`` (e.g. a model being trained), or a class or
    factory called with the env (for policies that read the env, such as
    :class:`~baselines.MinimumJerkController`; on the batched env it gets the vector env).
    ``keep_infos``: how many leading episodes keep their infos for plots. ``num_envs``: run
    on the batched env with ``min(num_envs, episodes)`` sub-envs (1: one single env). The env
    is created here and closed at the end; for a built-in policy that reads the planner's view
    (:func:`~baselines.policies.needs_planner_view`) with ``observation="planner"`` (the same
    scenes, dynamics and reward on the ids whose default is the learner's view).
    """
    sgc_env.check_env_id(env_id)
    if isinstance(episodes, bool) or not isinstance(episodes, int) or episodes < 1:
        raise ValueError(f"episodes must be an integer >= 1, got {episodes!r}")
    if isinstance(seed, bool) or not isinstance(seed, int | np.integer):
        raise ValueError(f"seed must be an integer, got {seed!r}")
    if isinstance(num_envs, bool) or not isinstance(num_envs, int) or num_envs < 1:
        raise ValueError(f"num_envs must be an integer >= 1, got {num_envs!r}")
    seed = int(seed)
    batched = min(num_envs, episodes) > 1
    kwargs = dict(env_kwargs or {})
    if isinstance(policy, str) and needs_planner_view(policy):
        kwargs.setdefault("observation", "planner")
    env: Any = (
        make_vec(env_id, min(num_envs, episodes), **kwargs)
        if batched
        else gym.make(env_id, **kwargs)
    )
    try:
        probe = env.envs[0] if batched else env.unwrapped
        if not hasattr(probe, "scenario"):
            raise ValueError(f"env_id: {env_id!r} is not an SGC environment (no scenario)")
        agent, default_label = _resolve_policy(policy, env, seed)
        name = label or default_label
        if batched:
            records = run_episodes_batched(
                agent, env, [seed + k for k in range(episodes)],
                tolerances=tolerances, keep_infos=keep_infos,
            )  # fmt: skip
        else:
            records = [
                run_episode(
                    agent,
                    env,
                    seed + k,
                    episode=k,
                    tolerances=tolerances,
                    keep_infos=k < keep_infos,
                )  # fmt: skip
                for k in range(episodes)
            ]
    finally:
        env.close()
    rows = [row for r in records for row in goal_rows(r, env_id, name)]
    summary = cast(
        Scorecard, {"env_id": env_id, "policy": name, "seed": seed, **summarize(records, rows)}
    )
    return EvaluationResult(env_id, name, seed, records, rows, summary)


def json_ready(value: Any) -> Any:
    """Nested value with numpy scalars as Python numbers and non-finite floats as None."""
    if isinstance(value, Mapping):
        return {str(k): json_ready(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [json_ready(v) for v in value]
    if isinstance(value, np.ndarray):
        return json_ready(value.tolist())
    if isinstance(value, np.bool_ | bool):
        return bool(value)
    if isinstance(value, np.integer):
        return int(value)
    if isinstance(value, float | np.floating):
        return float(value) if math.isfinite(value) else None
    return value


def _cell(value: Any) -> Any:
    ready = json_ready(value)
    return "" if ready is None else ready


def write_goals_csv(rows: Sequence[Mapping[str, Any]], path: str | Path) -> Path:
    """Per-goal rows as CSV (columns :data:`GOAL_COLUMNS`; empty cells for None / nan)."""
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    with out.open("w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=list(GOAL_COLUMNS), extrasaction="ignore")
        writer.writeheader()
        for row in rows:
            writer.writerow({k: _cell(row.get(k)) for k in GOAL_COLUMNS})
    return out


def write_summary_json(summary: Mapping[str, Any], path: str | Path) -> Path:
    """The scorecard as strict JSON (nan and inf become null)."""
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(json_ready(summary), indent=2, allow_nan=False) + "\n")
    return out
