"""GoalSpec lists from a resolved scenario, so rollouts of any env can be scored."""

from __future__ import annotations

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
            orientation = None
            angle = None
            if goal.relative_rotation is not None:
                rel = np.asarray(goal.relative_rotation, dtype=float)
                previous = Rotation.from_rotvec(rel) * previous
                orientation = tuple(float(x) for x in previous.as_quat())
                angle = float(np.linalg.norm(rel))
            elif goal.orientation is not None:
                previous = Rotation.from_quat(np.asarray(goal.orientation, dtype=float))
                orientation = tuple(float(x) for x in goal.orientation)
            has_nail = goal.nail is not None
            specs.append(
                GoalSpec(
                    time=float(goal.time),
                    nail=tuple(float(x) for x in goal.nail) if has_nail else None,
                    orientation=orientation,
                    point=tuple(float(x) for x in goal.point) if has_nail else None,
                    rotation_angle=angle,
                )
            )
        out.append(specs)
    return out
