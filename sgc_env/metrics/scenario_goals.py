"""GoalSpec lists from a resolved scenario, so rollouts of any env can be scored."""

from __future__ import annotations

from collections.abc import Sequence
from typing import cast

import numpy as np
from scipy.spatial.transform import Rotation

from sgc_env.metrics.trajectory import GoalSpec
from sgc_env.scenario import Scenario


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
        previous = Rotation.from_quat(np.asarray(body.orientation, dtype=float))
        specs = []
        for goal in body.goals:
            orientation: tuple[float, float, float, float] | None = None
            angle = None
            if goal.relative_rotation is not None:
                rel = np.asarray(goal.relative_rotation, dtype=float)
                previous = Rotation.from_rotvec(rel) * previous
                orientation = _quat(previous.as_quat())
                angle = float(np.linalg.norm(rel))
            elif goal.orientation is not None:
                previous = Rotation.from_quat(np.asarray(goal.orientation, dtype=float))
                orientation = _quat(goal.orientation)
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


def _quat(q: Sequence[float]) -> tuple[float, float, float, float]:
    x, y, z, w = (float(c) for c in q)
    return x, y, z, w
