"""Branches and functions that take one value (a Python float) or many (a numpy array) alike.

The env's task rules are written once, in plain arithmetic, and run on floats for one env and on
arrays over sub-envs for the batched env (``+ - * /`` mean the same on both; numpy evaluates
``a + b * c`` in Python's order, with no fused multiply-add, so each element equals the float
result bit for bit). What differs is a branch and a function call; these helpers dispatch on
the type. A branch on one value runs only the side taken (a float division by zero raises);
on arrays both sides run where the elements disagree (callers silence numpy's warnings of the
side not taken) and :func:`where` picks per element. ``atan2``, the one transcendental, goes
through ``math.atan2`` per element: numpy's SIMD versions may differ from libm's in the last
bit. ``sqrt`` is correctly rounded in both.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

__all__ = ["all_", "any_", "at_least", "at_most", "atan2", "rint", "sqrt", "where", "where3"]

Value = Any
"""A float (one env) or a numpy array (one entry per sub-env, or per sub-env and body)."""


# Many values are a numpy array (the class is tested, not isinstance: the single env's hot
# path); anything else is one value, a Python or numpy scalar, and takes Python's path (math's
# functions give Python floats for numpy scalars too, as the float code always did). The
# hottest rules test one value inline before calling, ``c is True or c is not False and
# all_(c)``: for one value a call costs more than the branch itself.


_count = np.count_nonzero  # a third of the cost of ndarray.any / .all on a rule's small arrays


def any_(condition: Value) -> bool:
    """Whether the condition holds anywhere (for one value: whether it holds)."""
    return condition if condition.__class__ is bool else _count(condition) != 0


def all_(condition: Value) -> bool:
    """Whether the condition holds everywhere (for one value: whether it holds)."""
    return condition if condition.__class__ is bool else _count(condition) == condition.size


def where(condition: Value, a: Value, b: Value) -> Value:
    """``a`` where the condition holds, else ``b`` (Python's ``a if condition else b``)."""
    if condition.__class__ is np.ndarray:
        return np.where(condition, a, b)
    return a if condition else b


def where3(condition: Value, a: Sequence[Any], b: Sequence[Any]) -> Any:
    """:func:`where` of each component of two 3-vectors."""
    if condition.__class__ is not np.ndarray:
        return a if condition else b
    return (
        np.where(condition, a[0], b[0]),
        np.where(condition, a[1], b[1]),
        np.where(condition, a[2], b[2]),
    )


def sqrt(x: Value) -> Value:
    return np.sqrt(x) if x.__class__ is np.ndarray else math.sqrt(x)


def atan2(y: Value, x: Value) -> Value:
    """``math.atan2``, per element on arrays (libm's result, as for one value)."""
    if y.__class__ is not np.ndarray:
        return math.atan2(y, x)
    if x.__class__ is not np.ndarray or x.shape != y.shape:
        x = np.broadcast_to(x, y.shape)
    out = list(map(math.atan2, y.ravel().tolist(), x.ravel().tolist()))
    return np.array(out, dtype=np.float64).reshape(y.shape)


def rint(x: Value) -> Value:
    """Round half to even (Python's ``round``, an int for one value; ``np.rint`` on arrays)."""
    return np.rint(x) if x.__class__ is np.ndarray else round(x)


def at_most(value: Value, cap: float) -> Value:
    """Python's ``min(value, cap)``: ``value`` unless ``cap < value`` (NaN stays NaN)."""
    if value.__class__ is np.ndarray:
        return np.where(cap < value, cap, value)
    return cap if cap < value else value


def at_least(value: Value, floor: float) -> Value:
    """Python's ``max(value, floor)``: ``value`` unless ``floor > value``."""
    if value.__class__ is np.ndarray:
        return np.where(floor > value, floor, value)
    return floor if floor > value else value
