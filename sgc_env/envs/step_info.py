"""The ``info`` of the env's ``reset`` and ``step`` (the info contract of docs/design.md).

Per-body entries are views of the step's packed record (one row per body), not copies: the
record is a fresh buffer every step, so infos handed out earlier keep their values.
"""

from __future__ import annotations

from typing import Any, TypedDict, cast

import numpy as np

from sgc_env.observation import BODY_BLOCK_SIZE, ObservationLayout

from .task import GoalEvent, GoalTask

__all__ = ["INFO_ARRAYS", "StepInfo", "info_arrays", "step_info"]

# Per-body columns of the (..., bodies, block) record that infos hand out as views; built once
# because constructing the index tuples costs as much as the slicing itself.
_BLOCK = ObservationLayout(1)


def _columns(name: str) -> tuple[Any, ...]:
    cols = _BLOCK.body_slice(0, name)
    return np.s_[..., cols] if cols.stop - cols.start > 1 else np.s_[..., cols.start]


_DEV, _ODEV = _columns("position_deviation"), _columns("orientation_deviation")
_PTL, _OTL = _columns("position_time_left"), _columns("orientation_time_left")
_POSITION, _ORIENTATION = _columns("position"), _columns("orientation")
_VELOCITY, _ANGULAR = _columns("linear_velocity"), _columns("angular_velocity")
_POINT_VELOCITY = _columns("point_velocity")


def info_arrays(
    time: Any, block: np.ndarray, tail: np.ndarray, goal_index: np.ndarray,
    orientation_goal_index: np.ndarray, spin_clamped: Any,
) -> dict[str, Any]:  # fmt: skip
    """The info's every-step entries in order, the per-body arrays views of a step record:
    ``block`` (..., bodies, block) and ``tail`` (3, ..., bodies, 3: points, forces, torques),
    where ``...`` is nothing for one env and the sub-envs for the batched env (one rule for
    both). The goal indices are handed out as given (copies: infos share no object)."""
    return {
        "time": time,
        "goal_index": goal_index,
        "orientation_goal_index": orientation_goal_index,
        "position_deviation": block[_DEV],
        "orientation_deviation": block[_ODEV],
        "time_to_goal": block[_PTL],
        "orientation_time_to_goal": block[_OTL],
        "body_position": block[_POSITION],
        "body_orientation": block[_ORIENTATION],
        "body_velocity": block[_VELOCITY],
        "body_angular_velocity": block[_ANGULAR],
        "point_position": tail[0],
        "point_velocity": block[_POINT_VELOCITY],
        "force": tail[1],
        "torque": tail[2],
        "spin_clamped": spin_clamped,
    }


INFO_ARRAYS = tuple(
    info_arrays(0.0, np.zeros((1, BODY_BLOCK_SIZE)), np.zeros((3, 1, 3)), np.zeros(1),
                np.zeros(1), False)
)[1:-1]  # fmt: skip
"""The info's per-body array keys in order (``time`` comes first, ``spin_clamped`` last)."""


class _StepInfoEveryStep(TypedDict):
    time: float
    goal_index: np.ndarray
    orientation_goal_index: np.ndarray
    position_deviation: np.ndarray
    orientation_deviation: np.ndarray
    time_to_goal: np.ndarray
    orientation_time_to_goal: np.ndarray
    body_position: np.ndarray
    body_orientation: np.ndarray
    body_velocity: np.ndarray
    body_angular_velocity: np.ndarray
    point_position: np.ndarray
    point_velocity: np.ndarray
    force: np.ndarray
    torque: np.ndarray
    spin_clamped: bool


class StepInfo(_StepInfoEveryStep, total=False):
    """The ``info`` of ``reset`` and ``step`` (see the module docstring): per-body arrays with
    one row per body; ``goal_reached`` only on a tick where goals fall."""

    goal_reached: list[GoalEvent]
    failure_charge: float  # SGCPointGoal-v1 on a failed step: the steps it did not get to


def step_info(
    block: np.ndarray,
    tail: np.ndarray,
    task: GoalTask,
    time: float,
    spin_clamped: bool,
    events: list[GoalEvent],
) -> StepInfo:
    """The info of one step from its record: ``block`` (bodies, block) and ``tail`` (point
    positions, forces, torques: 3, bodies, 3)."""
    info = cast(
        StepInfo,
        info_arrays(
            time, block, tail, task.goal_index.copy(), task.orientation_goal_index.copy(),
            spin_clamped,
        ),
    )
    if events:
        info["goal_reached"] = events
    return info
