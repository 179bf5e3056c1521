"""The infos of a batched step, read straight from the step's shared buffers.

The single env's info (:mod:`.step_info`) hands out views of its step record; the batched
task (:mod:`.batch_task`) keeps one (N, record) buffer per step, so the vector info dict's
arrays are views of its columns (Gymnasium's layout: per key an array over sub-envs and a
``_key`` mask) and SB3's per-sub-env dicts are rows of those views: no per-sub-env info is
built first. The values equal what ``batch_infos`` makes of the single envs' infos.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from sgc_env.observation import BODY_BLOCK_SIZE, ObservationLayout

from .batch_task import BatchTask
from .task import GoalEvent

__all__ = ["row_infos", "vector_infos"]

_L = ObservationLayout(1)
_BLOCK_KEYS = (
    ("position_deviation", "position_deviation"),
    ("orientation_deviation", "orientation_deviation"),
    ("time_to_goal", "position_time_left"),
    ("orientation_time_to_goal", "orientation_time_left"),
    ("body_position", "position"),
    ("body_orientation", "orientation"),
    ("body_velocity", "linear_velocity"),
    ("body_angular_velocity", "angular_velocity"),
)
_ORDER = (
    "goal_index", "orientation_goal_index", "position_deviation", "orientation_deviation",
    "time_to_goal", "orientation_time_to_goal", "body_position", "body_orientation",
    "body_velocity", "body_angular_velocity", "point_position", "point_velocity", "force",
    "torque",
)  # fmt: skip
"""``step_info``'s array keys in its order (``time`` comes first, ``spin_clamped`` last)."""


def _columns(task: BatchTask) -> dict[str, np.ndarray]:
    """Every per-body info array over sub-envs: (N, bodies[, 3]) views of the record."""
    n, b, size = task.n, task.b, task.size
    rec = task.rec
    block = rec[:, : size - 1].reshape(n, b, BODY_BLOCK_SIZE)
    tail = rec[:, size:].reshape(n, 3, b, 3)
    out = {
        "goal_index": task.goal_index.copy(),
        "orientation_goal_index": task.orientation_goal_index.copy(),
        "point_position": tail[:, 0],
        "point_velocity": block[..., _L.body_slice(0, "point_velocity")],
        "force": tail[:, 1],
        "torque": tail[:, 2],
    }
    for key, name in _BLOCK_KEYS:
        cols = _L.body_slice(0, name)
        out[key] = block[..., cols] if cols.stop - cols.start > 1 else block[..., cols.start]
    return {key: out[key] for key in _ORDER}


def vector_infos(task: BatchTask, events: dict[int, list[GoalEvent]]) -> dict[str, Any]:
    """Gymnasium's vector info of a step where every sub-env reported (stepped or reset)."""
    n = task.n
    values: dict[str, Any] = {"time": task.rec[:, task.size - 1].copy()}
    values.update(_columns(task))
    values["spin_clamped"] = task.spin.copy()
    out: dict[str, Any] = {}
    for key, value in values.items():
        out[key] = value
        out[f"_{key}"] = np.ones(n, dtype=bool)
    if events:
        reached = np.full(n, None, dtype=object)
        mask = np.zeros(n, dtype=bool)
        for i, happened in events.items():
            reached[i] = happened
            mask[i] = True
        out["goal_reached"] = reached
        out["_goal_reached"] = mask
    return out


def row_infos(task: BatchTask, events: dict[int, list[GoalEvent]]) -> list[dict[str, Any]]:
    """One info dict per sub-env (SB3's layout), each value a row of the step's arrays."""
    columns = _columns(task)
    keys = ("time", *columns, "spin_clamped")
    times = task.rec[:, task.size - 1].tolist()
    spins = task.spin.tolist()
    infos = [
        dict(zip(keys, (t, *row, s), strict=True))
        for t, s, *row in zip(times, spins, *columns.values(), strict=True)
    ]
    for i, happened in events.items():
        infos[i]["goal_reached"] = happened
    return infos
