"""The ``info`` of the env's ``reset`` and ``step`` (the info contract of docs/design.md).

Per-body entries are views of the step's packed record (one row per body), not copies: the
record is a fresh buffer every step, so infos handed out earlier keep their values.
"""

from __future__ import annotations

from typing import TypedDict

import numpy as np

from sgc_env.observation import ObservationLayout

from .task import GoalEvent, GoalTask

__all__ = ["StepInfo", "step_info"]

# Per-body columns of the (bodies, block) record that info hands out as views; built once
# because constructing the index tuples costs as much as the slicing itself.
_BLOCK = ObservationLayout(1)
_COL_DEV = np.s_[:, _BLOCK.body_slice(0, "position_deviation")]
_COL_POINT_VELOCITY = np.s_[:, _BLOCK.body_slice(0, "point_velocity")]
_COL_ODEV = np.s_[:, _BLOCK.body_slice(0, "orientation_deviation")]
_COL_PTL = np.s_[:, _BLOCK.body_slice(0, "position_time_left").start]
_COL_OTL = np.s_[:, _BLOCK.body_slice(0, "orientation_time_left").start]
_COL_POSITION = np.s_[:, _BLOCK.body_slice(0, "position")]
_COL_ORIENTATION = np.s_[:, _BLOCK.body_slice(0, "orientation")]
_COL_VELOCITY = np.s_[:, _BLOCK.body_slice(0, "linear_velocity")]
_COL_ANGULAR_VELOCITY = np.s_[:, _BLOCK.body_slice(0, "angular_velocity")]


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
    failure_charge: float  # SGCPointGoal-v0 on a failed step: the steps it did not get to


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
    info: StepInfo = {
        "time": time,
        "goal_index": task.goal_index.copy(),
        "orientation_goal_index": task.orientation_goal_index.copy(),
        "position_deviation": block[_COL_DEV],
        "orientation_deviation": block[_COL_ODEV],
        "time_to_goal": block[_COL_PTL],
        "orientation_time_to_goal": block[_COL_OTL],
        "body_position": block[_COL_POSITION],
        "body_orientation": block[_COL_ORIENTATION],
        "body_velocity": block[_COL_VELOCITY],
        "body_angular_velocity": block[_COL_ANGULAR_VELOCITY],
        "point_position": tail[0],
        "point_velocity": block[_COL_POINT_VELOCITY],
        "force": tail[1],
        "torque": tail[2],
        "spin_clamped": spin_clamped,
    }
    if events:
        info["goal_reached"] = events
    return info
