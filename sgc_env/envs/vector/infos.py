"""The infos of a batched step, read straight from the step's shared buffers.

The single env's info (:mod:`..step_info`) hands out views of its step record; the batched
task (:mod:`.task`) keeps one (N, record) buffer per step, so the vector info dict's
arrays are views of its columns (Gymnasium's layout: per key an array over sub-envs and a
``_key`` mask) and SB3's per-sub-env dicts are rows of those views: no per-sub-env info is
built first. Both read the record through :func:`~sgc_env.envs.step_info.info_arrays`, so the
values equal what ``batch_infos`` makes of the single envs' infos.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from sgc_env.observation import BODY_BLOCK_SIZE

from ..step_info import INFO_ARRAYS, info_arrays
from ..task import GoalEvent
from .task import BatchTask

__all__ = ["row_infos", "vector_infos"]


def _columns(task: BatchTask) -> dict[str, Any]:
    """Every every-step info entry over sub-envs: (N, bodies[, 3]) views of the record."""
    n, b, size = task.n, task.b, task.size
    rec = task.rec
    block = rec[:, : size - 1].reshape(n, b, BODY_BLOCK_SIZE)
    tail = rec[:, size:].reshape(n, 3, b, 3).transpose(1, 0, 2, 3)
    return info_arrays(
        rec[:, size - 1], block, tail, task.goal_index.copy(),
        task.orientation_goal_index.copy(), task.spin.copy(),
    )  # fmt: skip


def vector_infos(task: BatchTask, events: dict[int, list[GoalEvent]]) -> dict[str, Any]:
    """Gymnasium's vector info of a step where every sub-env reported (stepped or reset)."""
    n = task.n
    values = _columns(task)
    values["time"] = values["time"].copy()
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


def row_infos(
    task: BatchTask, events: dict[int, list[GoalEvent]], key: str, values: list[Any]
) -> list[dict[str, Any]]:
    """One info dict per sub-env (SB3's layout), each value a row of the step's arrays, made
    when the dict is first read (:class:`RowInfo`); ``key`` holds ``values[i]`` in dict i
    (the caller's own entry, e.g. SB3's ``TimeLimit.truncated``)."""
    columns = _columns(task)
    infos: list[dict[str, Any]] = [
        RowInfo(columns, i, key, value) for i, value in enumerate(values)
    ]
    for i, happened in events.items():
        infos[i]["goal_reached"] = happened
    return infos


_LAZY = frozenset(("time", *INFO_ARRAYS, "spin_clamped"))
_dict_set = dict.__setitem__


def _filling(name: str) -> Any:
    method = getattr(dict, name)

    def call(self: RowInfo, *args: Any, **kwargs: Any) -> Any:
        self.fill()
        return method(self, *args, **kwargs)

    call.__name__ = name
    return call


class RowInfo(dict[str, Any]):
    """A sub-env's info whose per-step entries (``step_info``'s keys, in its order) are made
    from the step's arrays when it is first read. Why: SB3's API wants one dict per sub-env,
    and 16 numpy views per sub-env and step cost about as much as the whole batched step, while
    the training loop reads only a few keys it sets itself (``episode``,
    ``terminal_observation``). Every read of the dict as a whole fills it first; ``copy`` and
    pickling give plain dicts."""

    __slots__ = ("_row",)

    def __init__(self, columns: dict[str, np.ndarray], row: int, key: str, value: Any) -> None:
        _dict_set(self, key, value)  # dict's own (half the cost of dict.__init__ with a pair)
        self._row: tuple[dict[str, np.ndarray], int] | None = (columns, row)

    def fill(self) -> None:
        """Make the per-step entries (first, as in the single env's info)."""
        if self._row is None:
            return
        columns, i = self._row
        self._row = None
        added = dict.copy(self)
        dict.clear(self)
        dict.__setitem__(self, "time", float(columns["time"][i]))
        for key in INFO_ARRAYS:
            dict.__setitem__(self, key, columns[key][i])
        dict.__setitem__(self, "spin_clamped", bool(columns["spin_clamped"][i]))
        dict.update(self, added)

    def __getitem__(self, key: Any) -> Any:
        if self._row is not None and key in _LAZY:
            self.fill()
        return dict.__getitem__(self, key)

    def get(self, key: Any, default: Any = None) -> Any:
        if self._row is not None and key in _LAZY:
            self.fill()
        return dict.get(self, key, default)

    def __contains__(self, key: object) -> bool:
        return (self._row is not None and key in _LAZY) or dict.__contains__(self, key)

    def __setitem__(self, key: Any, value: Any) -> None:
        if self._row is not None and key in _LAZY:
            self.fill()
        dict.__setitem__(self, key, value)

    def __reduce__(self) -> tuple[Any, ...]:
        self.fill()
        return (dict, (dict.copy(self),))

    __iter__ = _filling("__iter__")
    __len__ = _filling("__len__")
    __repr__ = _filling("__repr__")
    __eq__ = _filling("__eq__")
    __ne__ = _filling("__ne__")
    __delitem__ = _filling("__delitem__")
    __reversed__ = _filling("__reversed__")
    __or__ = _filling("__or__")
    __ror__ = _filling("__ror__")
    __ior__ = _filling("__ior__")
    keys = _filling("keys")
    items = _filling("items")
    values = _filling("values")
    copy = _filling("copy")
    pop = _filling("pop")
    popitem = _filling("popitem")
    setdefault = _filling("setdefault")
    update = _filling("update")
