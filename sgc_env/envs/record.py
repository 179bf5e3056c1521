"""The step record: every double a step hands out, for one env or for many, written once.

Per body the planner's block (:data:`sgc_env.observation.BODY_FIELDS`, residual slots holding
residuals), then the time, then per body the tracked point, then the applied forces and
torques. Observation views (:mod:`.views`) read the record, and the info's per-body arrays are
views of it (:mod:`.step_info`). :func:`body_block` lists one body's entries, floats for one
env or arrays over sub-envs (and bodies) for the batched env; :func:`residuals` and the packing
differ by type only: one struct round trip for floats (for a few bodies several times cheaper
than numpy on tiny arrays), one cast of a whole array for the batch.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from sgc_env.observation import float32_residuals

Vec = Sequence[Any]  # components: floats for one env, arrays for the batch

__all__ = ["body_block", "pack_blocks", "residuals"]


def _stacked(values: list[Any]) -> np.ndarray:
    """The values (arrays, or floats for all) as one array, the first axis theirs: one call
    when they are arrays of one shape (the batch's), else broadcast first."""
    try:
        return np.array(values, dtype=np.float64)
    except ValueError:  # floats among arrays, or shapes that only broadcast
        return np.array(np.broadcast_arrays(*values))


def residuals(values: list[Any]) -> list[Any]:
    """``x - float32(x)`` of every value (what the float32 observation loses)."""
    if values[0].__class__ is not np.ndarray:
        return float32_residuals(values)
    exact = _stacked(values)
    return list(exact - exact.astype(np.float32).astype(np.float64))


def body_block(
    state: Vec, offset: Vec, deviation: Vec, position_left: Any, position_course: Vec,
    phi: Vec, orientation_left: Any, orientation_course: Vec, offset_residual: Vec,
) -> list[Any]:  # fmt: skip
    """One body's block in :data:`~sgc_env.observation.BODY_FIELDS` order (the residual
    slots in ``RESIDUAL_FIELDS`` order, pinned by a test; the point offset's is cached with
    the goal)."""
    pos, orn, lin, ang = state
    return [
        *pos, *orn, *lin, *ang, *offset, *deviation, position_left, *position_course, *phi,
        orientation_left, *orientation_course,
        *residuals([*deviation, *orn, *ang, *lin, *phi, position_left, orientation_left]),
        *offset_residual,
    ]  # fmt: skip


def pack_blocks(entries: list[Any], out: np.ndarray) -> None:
    """Write :func:`body_block`'s entries, each an array over (bodies, sub-envs) or a float
    for all, into the batch's (sub-envs, bodies, block) array ``out``."""
    out[...] = _stacked(entries).T
