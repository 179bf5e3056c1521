"""Named slices of the flat observation (the observation contract of docs/design.md).

Policies and metrics address observation entries by name through :class:`ObservationLayout`
so that nobody hard-codes offsets.
"""

from __future__ import annotations

import operator
import struct
from collections.abc import Sequence
from dataclasses import dataclass, field
from functools import cache, cached_property

import numpy as np

__all__ = [
    "BASE_BLOCK_SIZE",
    "BASE_FIELDS",
    "BODY_BLOCK_SIZE",
    "BODY_FIELDS",
    "GLOBAL_FIELDS",
    "RESIDUAL_FIELDS",
    "ObservationLayout",
    "float32_residuals",
]

BASE_FIELDS: tuple[tuple[str, int], ...] = (
    ("position", 3),
    ("orientation", 4),
    ("linear_velocity", 3),
    ("angular_velocity", 3),
    ("point_offset", 3),
    ("position_deviation", 3),
    ("point_velocity", 3),
    ("position_time_left", 1),
    ("position_course_start", 3),
    ("position_course_duration", 1),
    ("position_next_start", 3),
    ("position_next_duration", 1),
    ("position_end_velocity", 3),
    ("position_flags", 2),
    ("orientation_deviation", 3),
    ("orientation_time_left", 1),
    ("orientation_course_start", 3),
    ("orientation_course_duration", 1),
    ("orientation_next_start", 3),
    ("orientation_next_duration", 1),
    ("orientation_end_velocity", 3),
    ("orientation_flags", 2),
)
GLOBAL_FIELDS: tuple[tuple[str, int], ...] = (("time", 1),)

RESIDUAL_FIELDS: tuple[str, ...] = (
    "position_deviation",
    "point_velocity",
    "orientation",
    "angular_velocity",
    "linear_velocity",
    "orientation_deviation",
    "position_time_left",
    "orientation_time_left",
    "point_offset",
)
"""Fields whose double-precision value a policy may need: each gets a ``<field>_residual``.

float32 resolves about 6e-8 of a value, not enough to put a body on a nail to 1e-9 m from the
observation alone; ``float64(x) + float64(x_residual)`` recovers the double to ~1e-15.
"""

_SIZES = dict(BASE_FIELDS)
BODY_FIELDS: tuple[tuple[str, int], ...] = BASE_FIELDS + tuple(
    (f"{name}_residual", _SIZES[name]) for name in RESIDUAL_FIELDS
)

_BODY_OFFSETS: dict[str, tuple[int, int]] = {}
_start = 0
for _name, _size in BODY_FIELDS:
    _BODY_OFFSETS[_name] = (_start, _start + _size)
    _start += _size
BODY_BLOCK_SIZE = _start
BASE_BLOCK_SIZE = sum(size for _, size in BASE_FIELDS)


def float32_residuals(values: Sequence[float]) -> list[float]:
    """``x - float32(x)`` for every value: what storing ``x`` as float32 loses.

    Stored as float32 again, the residual recovers the double to ~1e-15 relative. Computed on
    plain floats because it runs every control step on about two dozen values: one struct
    round trip rounds them all to float32 (the C cast numpy's ``astype`` uses), about four
    times cheaper than the mixed-dtype numpy subtraction. Values too large for float32 fall
    back to numpy, which rounds them to infinity like the observation itself.
    """
    fmt = _float32_struct(len(values))
    try:
        rounded: Sequence[float] = fmt.unpack(fmt.pack(*values))
    except OverflowError:
        with np.errstate(over="ignore"):
            rounded = np.asarray(values, dtype=np.float64).astype(np.float32).tolist()
    return list(map(operator.sub, values, rounded))


@cache
def _float32_struct(n: int) -> struct.Struct:
    return struct.Struct(f"{n}f")


@dataclass(frozen=True)
class ObservationLayout:
    """Offsets of every named entry for a scene with ``n_bodies`` bodies.

    Body blocks come first, in scenario body order, followed by the global entries.
    """

    n_bodies: int
    body_names: tuple[str, ...] = field(default=())

    def __post_init__(self) -> None:
        if self.n_bodies < 1:
            raise ValueError(f"n_bodies must be >= 1, got {self.n_bodies}")
        if self.body_names and len(self.body_names) != self.n_bodies:
            raise ValueError("body_names must have one name per body")

    @property
    def body_block_size(self) -> int:
        return BODY_BLOCK_SIZE

    @property
    def size(self) -> int:
        return self.n_bodies * BODY_BLOCK_SIZE + sum(n for _, n in GLOBAL_FIELDS)

    @cached_property
    def residual_mask(self) -> np.ndarray:
        """True on every ``*_residual`` entry of the flat observation."""
        mask = np.zeros(self.size, dtype=bool)
        for i in range(self.n_bodies):
            start = self.body_offset(i)
            mask[start + BASE_BLOCK_SIZE : start + BODY_BLOCK_SIZE] = True
        mask.flags.writeable = False
        return mask

    def body_offset(self, body_index: int) -> int:
        if not 0 <= body_index < self.n_bodies:
            raise IndexError(f"body_index {body_index} out of range for {self.n_bodies} bodies")
        return body_index * BODY_BLOCK_SIZE

    def has_body_field(self, field_name: str) -> bool:
        return field_name in _BODY_OFFSETS

    def body_slice(self, body_index: int, field_name: str) -> slice:
        """Slice of ``field_name`` of body ``body_index`` in the flat observation."""
        if field_name not in _BODY_OFFSETS:
            raise KeyError(f"unknown body field {field_name!r}; known: {sorted(_BODY_OFFSETS)}")
        a, b = _BODY_OFFSETS[field_name]
        base = self.body_offset(body_index)
        return slice(base + a, base + b)

    def global_slice(self, field_name: str) -> slice:
        start = self.n_bodies * BODY_BLOCK_SIZE
        for name, n in GLOBAL_FIELDS:
            if name == field_name:
                return slice(start, start + n)
            start += n
        raise KeyError(f"unknown global field {field_name!r}")

    def unpack(self, observation: np.ndarray) -> list[dict[str, np.ndarray]]:
        """Per-body dictionaries of views into ``observation`` (for debugging and tests)."""
        obs = np.asarray(observation)
        if obs.shape[-1] != self.size:
            raise ValueError(f"observation has {obs.shape[-1]} entries, layout expects {self.size}")
        return [
            {name: obs[..., self.body_slice(i, name)] for name, _ in BODY_FIELDS}
            for i in range(self.n_bodies)
        ]
