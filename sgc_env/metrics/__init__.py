"""Metrics from rollouts: exactness, punctuality, smoothness, effort, success.

Two layers: pure signal functions (`sgc_env.metrics.signals`) and scorecards built from the
per-step infos of a rollout (`BodyTrajectory`, `score_body`, `score_episode`). See
docs/metrics.md for definitions, units, defaults and pitfalls.
"""

from sgc_env.metrics.scenario_goals import goals_from_scenario
from sgc_env.metrics.scoring import (
    MIN_COURSE_SAMPLES,
    MINIMA_RELATIVE_PROMINENCE,
    SPARC_CYCLES_PER_COURSE,
    STILL_SPEED,
    score_body,
    score_episode,
)
from sgc_env.metrics.signals import (
    angle_travelled,
    closest_approach,
    first_entry,
    integral_of_squares,
    interpolate_at,
    ldlj,
    rotation_ratio,
    sparc,
    speed_minima,
    step_weights,
    velocity_jump,
)
from sgc_env.metrics.trajectory import BodyTrajectory, GoalSpec, Tolerances

__all__ = [
    "MIN_COURSE_SAMPLES",
    "MINIMA_RELATIVE_PROMINENCE",
    "SPARC_CYCLES_PER_COURSE",
    "STILL_SPEED",
    "BodyTrajectory",
    "GoalSpec",
    "Tolerances",
    "angle_travelled",
    "closest_approach",
    "first_entry",
    "goals_from_scenario",
    "integral_of_squares",
    "interpolate_at",
    "ldlj",
    "rotation_ratio",
    "score_body",
    "score_episode",
    "sparc",
    "speed_minima",
    "step_weights",
    "velocity_jump",
]
