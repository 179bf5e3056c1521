"""Values read from YAML or JSON checked against the type hints of what will receive them.

A hyperparameter file or a recipe feeds SB3 constructors and ``TrainConfig``; a string where
an integer belongs fails deep inside training with a ``TypeError``. Checking each value
against the receiver's own annotation (``int``, ``float``, ``bool``, ``str``, ``None``,
mappings, unions of those) reports it at once, naming the field. Annotations this cannot
judge (classes, schedules given as callables) are left to the receiver.
"""

from __future__ import annotations

import collections.abc
import math
import types
import typing
from pathlib import Path
from typing import Any

__all__ = ["check_weight", "describe", "matches"]

_NAMES = {bool: "true/false", int: "an integer", float: "a finite number", str: "a string",
          type(None): "null", dict: "a mapping", Path: "a path"}  # fmt: skip


def matches(value: Any, annotation: Any) -> bool | None:
    """Whether ``value`` fits ``annotation``; None when the annotation is beyond this check."""
    origin = typing.get_origin(annotation)
    if origin in (typing.Union, types.UnionType):
        verdicts = [matches(value, arg) for arg in typing.get_args(annotation)]
        if True in verdicts:
            return True
        return None if None in verdicts else False
    if annotation is type(None):
        return value is None
    if annotation is bool:
        return isinstance(value, bool)
    if annotation is int:
        return isinstance(value, int) and not isinstance(value, bool)
    if annotation is float:
        real = isinstance(value, (int, float)) and not isinstance(value, bool)
        return real and math.isfinite(value)
    if annotation in (str, Path):
        return isinstance(value, str)
    if annotation is dict or origin is dict:
        return isinstance(value, dict)
    if origin is collections.abc.Callable:
        return callable(value)
    return None


def describe(annotation: Any) -> str:
    """``an integer``, ``a finite number or null`` ... for error messages."""
    if typing.get_origin(annotation) in (typing.Union, types.UnionType):
        return " or ".join(describe(arg) for arg in typing.get_args(annotation))
    if typing.get_origin(annotation) is collections.abc.Callable:
        return "a schedule"
    base = typing.get_origin(annotation) or annotation
    return _NAMES.get(base, getattr(base, "__name__", str(base)))


def check_weight(value: Any, name: str) -> float:
    """``value`` as a float when it is a finite number >= 0 (a loss or reward weight; ``True``
    is not a number here); otherwise a ValueError naming ``name``."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not (
        math.isfinite(value) and value >= 0
    ):
        raise ValueError(f"{name}: expected a finite weight >= 0, got {value!r}")
    return float(value)
