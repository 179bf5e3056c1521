"""GoalSpec lists from a resolved scenario, so rollouts of any env can be scored."""

from __future__ import annotations

from collections.abc import Sequence
from typing import cast

import numpy as np

from sgc_env.metrics.trajectory import GoalSpec
from sgc_env.scenario import Scenario
from sgc_env.scenario.model import goal_orientations


def goals_from_scenario(scenario: Scenario) -> list[list[GoalSpec]]:
    """Per body, its goals as `GoalSpec`s (nail, target orientation, body point, time).

    A `relative_rotation` goal's target is Exp(r) applied to the previous orientation goal's
    target (or the initial orientation), as the env does, and its length becomes the
    orientation course's `rotation_angle`, so a somersault's needed angle is its full length.
    """
    if not scenario.resolved:
        raise ValueError("scenario must be resolved (see sgc_env.scenario.resolve_scenario)")
    out: list[list[GoalSpec]] = []
    for body in scenario.bodies:
        specs = []
        for goal, orientation in zip(body.goals, goal_orientations(body), strict=True):
            angle = None
            if goal.relative_rotation is not None:
                angle = float(np.linalg.norm(np.asarray(goal.relative_rotation, dtype=float)))
            specs.append(
                GoalSpec(
                    time=float(cast(float, goal.time)),  # resolved: every goal has its time
                    nail=None if goal.nail is None else _vec3(goal.nail),
                    orientation=orientation,
                    point=None if goal.nail is None else _vec3(goal.point),
                    rotation_angle=angle,
                )
            )
        out.append(specs)
    return out


def _vec3(v: Sequence[float]) -> tuple[float, float, float]:
    x, y, z = (float(c) for c in v)
    return x, y, z

