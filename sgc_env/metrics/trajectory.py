"""Per-body sampled trajectories recovered from rollout infos, and goal descriptions."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation, Slerp

from sgc_env.defaults import ORIENTATION_TOLERANCE, POSITION_TOLERANCE
from sgc_env.metrics.signals import FloatArray, as_finite_array, check_times, locate


@dataclass(frozen=True)
class GoalSpec:
    """One goal of one body, as the metrics need it.

    `nail` is the world point the tracked body point must reach (None: orientation-only goal);
    `orientation` the target quaternion xyzw (None: position-only goal). `point` is the body
    frame offset of the tracked point; None means "use the env's `point_position`", which is
    right as long as every goal of the body tracks the same point. `rotation_angle` overrides
    the rotation the course ending here needs (rad), for somersaults longer than pi.
    """

    time: float
    nail: tuple[float, float, float] | None = None
    orientation: tuple[float, float, float, float] | None = None
    point: tuple[float, float, float] | None = None
    rotation_angle: float | None = None

    def __post_init__(self) -> None:
        if not math.isfinite(self.time):
            raise ValueError(f"time must be finite, got {self.time}")
        if self.nail is None and self.orientation is None:
            raise ValueError("a goal needs a nail, an orientation or both")
        for name, size in (("nail", 3), ("orientation", 4), ("point", 3)):
            value = getattr(self, name)
            if value is not None:
                arr = as_finite_array(value, name, ndim=1)
                if arr.size != size:
                    raise ValueError(f"{name} must have {size} entries, got {arr.size}")
        if self.orientation is not None and np.linalg.norm(self.orientation) < 1e-9:
            raise ValueError("orientation must be a nonzero quaternion")
        if self.rotation_angle is not None and not self.rotation_angle >= 0.0:
            raise ValueError(f"rotation_angle must be >= 0, got {self.rotation_angle}")


@dataclass(frozen=True)
class Tolerances:
    """What counts as meeting a goal: position (m) and orientation (rad) errors at the goal's
    own time (the state interpolated there when it falls between ticks), or, with ``time`` > 0
    (s), at any tick within that much of it.

    Why ``time=0`` by default: punctuality is half of the task; a looser rule is an explicit
    choice (``sgc evaluate --tolerance-time S``).
    """

    position: float = POSITION_TOLERANCE
    orientation: float = ORIENTATION_TOLERANCE
    time: float = 0.0

    def __post_init__(self) -> None:
        for name in ("position", "orientation"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0.0):
                raise ValueError(f"{name} tolerance must be finite and positive, got {value}")
        if not (math.isfinite(self.time) and self.time >= 0.0):
            raise ValueError(f"time tolerance must be finite and >= 0, got {self.time}")


def _stack(infos: Sequence[Mapping[str, Any]], key: str, body_index: int) -> FloatArray:
    try:
        rows = [np.asarray(info[key], dtype=float)[body_index] for info in infos]
    except KeyError as exc:
        raise ValueError(f"infos lack the key {key!r}") from exc
    except IndexError as exc:
        raise ValueError(f"body_index {body_index} out of range for {key!r}") from exc
    return as_finite_array(np.stack(rows), key, ndim=2)


@dataclass(frozen=True)
class BodyTrajectory:
    """Samples of one body after each control step (time strictly increasing).

    Velocities are the ones PyBullet reports after the step, i.e. the velocity held over the
    step (t_k - dt, t_k]. Forces and torques are the ones applied in that step.
    """

    times: FloatArray
    dt: float
    body_position: FloatArray
    body_velocity: FloatArray
    body_orientation: FloatArray
    body_angular_velocity: FloatArray
    point_position: FloatArray
    point_velocity: FloatArray
    force: FloatArray
    torque: FloatArray

    def __post_init__(self) -> None:
        check_times(self.times)
        if not (math.isfinite(self.dt) and self.dt > 0.0):
            raise ValueError(f"dt must be finite and positive, got {self.dt}")
        n = self.times.shape[0]
        for name in (
            "body_position",
            "body_velocity",
            "body_angular_velocity",
            "point_position",
            "point_velocity",
            "force",
            "torque",
        ):
            arr = getattr(self, name)
            if arr.shape != (n, 3):
                raise ValueError(f"{name} must have shape ({n}, 3), got {arr.shape}")
        if self.body_orientation.shape != (n, 4):
            raise ValueError(
                f"body_orientation must have shape ({n}, 4), got {self.body_orientation.shape}"
            )

    @classmethod
    def from_infos(
        cls,
        infos: Sequence[Mapping[str, Any]],
        body_index: int,
        dt: float,
        initial_info: Mapping[str, Any] | None = None,
    ) -> BodyTrajectory:
        """Build from the per-step info dicts of a rollout (see docs/design.md, info contract).

        `initial_info` (optional) is the state before the first step, e.g. the reset info, in
        the same layout; its time defaults to 0 and its force and torque are taken as zero
        (nothing was applied yet). Without it the trajectory starts after the first step, and
        quantities at the start time (the first course's start point and orientation) are
        read from that first sample.
        """
        if len(infos) == 0:
            raise ValueError("infos must not be empty")
        if body_index < 0:
            raise ValueError(f"body_index must be >= 0, got {body_index}")
        rows = list(infos)
        if initial_info is not None:
            first = dict(initial_info)
            first.setdefault("time", 0.0)
            zeros = np.zeros_like(np.asarray(rows[0]["force"], dtype=float))
            first["force"] = zeros
            first["torque"] = zeros
            rows.insert(0, first)
        times = check_times([float(info["time"]) for info in rows], "infos' time")
        return cls(
            times=times,
            dt=float(dt),
            body_position=_stack(rows, "body_position", body_index),
            body_velocity=_stack(rows, "body_velocity", body_index),
            body_orientation=_stack(rows, "body_orientation", body_index),
            body_angular_velocity=_stack(rows, "body_angular_velocity", body_index),
            point_position=_stack(rows, "point_position", body_index),
            point_velocity=_stack(rows, "point_velocity", body_index),
            force=_stack(rows, "force", body_index),
            torque=_stack(rows, "torque", body_index),
        )

    def rotations(self) -> Rotation:
        """The body orientations as one scipy Rotation (quaternions xyzw)."""
        return Rotation.from_quat(self.body_orientation)

    def tracked_point(self, offset: Sequence[float] | None) -> tuple[FloatArray, FloatArray]:
        """World position and velocity of a body-frame point (None: the env's tracked point)."""
        if offset is None:
            return self.point_position, self.point_velocity
        r_world = self.rotations().apply(np.asarray(offset, dtype=float))
        position = self.body_position + r_world
        velocity = self.body_velocity + np.cross(self.body_angular_velocity, r_world)
        return position, velocity

    def orientation_at(self, t: float) -> Rotation:
        """Orientation at time t: the sample on a tick, slerp between ticks, clamped outside."""
        k, on_tick = locate(self.times, t)
        if on_tick:
            return Rotation.from_quat(self.body_orientation[k])
        if k < 0:
            return Rotation.from_quat(self.body_orientation[0])
        if k == self.times.size - 1:
            return Rotation.from_quat(self.body_orientation[-1])
        pair = Rotation.from_quat(self.body_orientation[k : k + 2])
        return Slerp(self.times[k : k + 2], pair)([t])[0]

    def orientation_error(self, target: Sequence[float]) -> FloatArray:
        """Angle (rad, in [0, pi]) between each sampled orientation and `target` (xyzw)."""
        goal = Rotation.from_quat(np.asarray(target, dtype=float))
        return (self.rotations() * goal.inv()).magnitude()

    def orientation_offset(
        self, target: Sequence[float], samples: slice = slice(None)
    ) -> FloatArray:
        """Rotation vectors of the sampled orientations (``samples`` of them) relative to
        `target` (xyzw).

        Principal vectors: continuous wherever the angle stays below pi, which is where a
        closest approach is refined.
        """
        goal = Rotation.from_quat(np.asarray(target, dtype=float))
        return (Rotation.from_quat(self.body_orientation[samples]) * goal.inv()).as_rotvec()
