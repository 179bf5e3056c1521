"""The one decoder of the flat observation for model-based policies (expert and comparisons).

A policy needs the observation in double precision: each field that has a ``<field>_residual``
is read as ``float32 value + residual`` (see :data:`sgc_env.observation.RESIDUAL_FIELDS`). The
offsets of every field a policy reads are looked up once per body (:class:`BodyFields`); the
expert reads them from a Python list of the observation's values on its hot path, the
comparison controllers get numpy arrays through :func:`read_body`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from sgc_env.observation import ObservationLayout

__all__ = ["COURSE_SIZE", "BodyFields", "BodyObservation", "TrackFields", "read_body"]


_COURSE_FIELDS = ("course_start", "course_duration", "next_start", "next_duration",
                  "end_velocity", "flags")  # fmt: skip
_COURSE_LAYOUT = [(0, 3), (3, 4), (4, 7), (7, 8), (8, 11), (11, 13)]
COURSE_SIZE = 13
"""The course constants are contiguous in a body block: 3 + 1 + 3 + 1 + 3 + 2 entries."""


class TrackFields:
    """Offsets of one track's entries: ``deviation`` and ``time_left`` as (value, residual)
    starts, ``flags`` and ``course`` (the :data:`COURSE_SIZE` course constants) as starts."""

    __slots__ = ("deviation", "time_left", "time_left_residual", "flags", "course")

    def __init__(self, layout: ObservationLayout, body: int, name: str) -> None:
        def at(field: str) -> int:
            return layout.body_slice(body, f"{name}_{field}").start

        self.deviation = (at("deviation"), at("deviation_residual"))
        self.time_left, self.time_left_residual = at("time_left"), at("time_left_residual")
        self.flags = at("flags")
        self.course = at("course_start")
        slices = [layout.body_slice(body, f"{name}_{x}") for x in _COURSE_FIELDS]
        if [(sl.start - self.course, sl.stop - self.course) for sl in slices] != _COURSE_LAYOUT:
            raise ValueError("the course constants are not contiguous in the observation layout")


class BodyFields:
    """Offsets of one body's entries, each a (value start, residual start) pair."""

    __slots__ = (
        "orientation", "angular_velocity", "linear_velocity", "point_offset", "point_velocity",
        "position_track", "orientation_track",
    )  # fmt: skip

    def __init__(self, layout: ObservationLayout, index: int) -> None:
        def at(field: str) -> tuple[int, int]:
            return (
                layout.body_slice(index, field).start,
                layout.body_slice(index, f"{field}_residual").start,
            )

        self.orientation = at("orientation")
        self.angular_velocity = at("angular_velocity")
        self.linear_velocity = at("linear_velocity")
        self.point_offset = at("point_offset")
        self.point_velocity = at("point_velocity")
        self.position_track = TrackFields(layout, index, "position")
        self.orientation_track = TrackFields(layout, index, "orientation")

    def track(self, name: str) -> TrackFields:
        return self.position_track if name == "position" else self.orientation_track

    def rotation(self, o: list[float]) -> tuple[float, float, float, float]:
        """The body's unit quaternion (xyzw) in double precision."""
        a, r = self.orientation
        x, y, z, w = o[a] + o[r], o[a + 1] + o[r + 1], o[a + 2] + o[r + 2], o[a + 3] + o[r + 3]
        norm = math.sqrt(x * x + y * y + z * z + w * w)
        return (x / norm, y / norm, z / norm, w / norm)

    @staticmethod
    def vec(o: list[float], at: tuple[int, int]) -> tuple[float, float, float]:
        """Double-precision 3-vector: float32 entries plus their residuals."""
        a, r = at
        return (o[a] + o[r], o[a + 1] + o[r + 1], o[a + 2] + o[r + 2])


@dataclass(frozen=True)
class BodyObservation:
    """One body's observation block in double precision (float32 value + residual)."""

    orientation: np.ndarray
    angular_velocity: np.ndarray
    linear_velocity: np.ndarray
    point_offset: np.ndarray
    point_velocity: np.ndarray
    position: dict[str, np.ndarray]
    orientation_track: dict[str, np.ndarray]

    def track(self, name: str) -> dict[str, np.ndarray]:
        return self.position if name == "position" else self.orientation_track


def read_body(model_or_layout, observation: np.ndarray, body: int) -> BodyObservation:
    """Body ``body``'s fields as arrays, through :class:`BodyFields` (``model_or_layout``: an
    env model with a ``layout`` or the :class:`ObservationLayout` itself)."""
    layout = getattr(model_or_layout, "layout", model_or_layout)
    fields = BodyFields(layout, body)
    o = np.asarray(observation, dtype=np.float64)

    def double(at: tuple[int, int], size: int) -> np.ndarray:
        a, r = at
        return o[a : a + size] + o[r : r + size]

    def track(t: TrackFields) -> dict[str, np.ndarray]:
        c = t.course
        out = {
            "deviation": double(t.deviation, 3),
            "time_left": double((t.time_left, t.time_left_residual), 1),
        }
        for name, (a, b) in zip(_COURSE_FIELDS, _COURSE_LAYOUT, strict=True):
            out[name] = o[c + a : c + b]
        return out

    q = double(fields.orientation, 4)
    return BodyObservation(
        orientation=q / np.linalg.norm(q),
        angular_velocity=double(fields.angular_velocity, 3),
        linear_velocity=double(fields.linear_velocity, 3),
        point_offset=double(fields.point_offset, 3),
        point_velocity=double(fields.point_velocity, 3),
        position=track(fields.position_track),
        orientation_track=track(fields.orientation_track),
    )
