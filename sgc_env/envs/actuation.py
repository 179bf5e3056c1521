"""Actions to wrenches: the one place that scales, clips and applies an env's action.

Like panda-gym's ``robot.set_action``: the env hands the clipped action and the bodies' states
at the start of the control step to :meth:`Actuation.drives`, which returns what
:meth:`~sgc_env.simulator.Simulator.step_bodies` holds for the period (force at the centre of
mass, torque scaled per principal axis, the CoM path the force acts at) and the applied
wrench the info reports. The single env and every sub-env of the batched env go through the
same code, so their forces agree bit for bit. Per-step work is plain-Python arithmetic on
tuples: for a few bodies that is several times cheaper than numpy calls.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from sgc_env.paper.quaternion import rotate, rotate_back
from sgc_env.scenario import Scenario
from sgc_env.simulator import BodyReading, Drive, Simulator

__all__ = ["Actuation", "body_drive", "clip_action"]


def clip_action(action: object, shape: tuple[int, ...]) -> list[float]:
    """The action as clipped floats; a ``TypeError`` / ``ValueError`` for a non-real dtype, a
    wrong shape or a non-finite entry (out-of-range finite entries are clipped to [-1, 1])."""
    a = action if type(action) is np.ndarray else np.asarray(action)
    if a.dtype.kind not in "fiu":
        raise TypeError(f"action must hold real numbers, got dtype {a.dtype}: {action!r}")
    if a.shape != shape:
        raise ValueError(f"action has shape {a.shape}, expected {shape}")
    values = a.tolist()
    hi, lo = max(values), min(values)
    if hi > 1.0 or lo < -1.0:
        if hi == math.inf or lo == -math.inf:
            raise ValueError(f"action contains non-finite values: {values}")
        values = [-1.0 if x < -1.0 else 1.0 if x > 1.0 else x for x in values]
    # Clipped first, so the sum cannot overflow: it is NaN only if an entry is.
    if math.isnan(sum(values)):
        raise ValueError(f"action contains non-finite values: {values}")
    return values


def body_drive(
    action: Sequence[Any], position: Sequence[Any], orientation: Sequence[Any],
    velocity: Sequence[Any], force_limit: Any, torque_scale: Sequence[Any], mass: Any,
    gravity: Sequence[Any], coef: Sequence[tuple[Any, Any]],
) -> tuple[tuple, tuple | None, list[tuple]]:  # fmt: skip
    """One body's control period, the actuation rule of both envs (floats for one env, arrays
    over sub-envs for the batched env): the force and torque (world frame) from its action
    entries, force xyz then torque xyz (no torque for 3 entries), and its state at the step's
    start; and the centre of mass before each substep under semi-implicit Euler,
    ``x + k h v + h^2 a k (k + 1) / 2`` (``coef`` holds ``(k h, h^2 k (k + 1) / 2)``; the
    batch passes one pair of arrays over the substeps), where the force acts."""
    fx, fy, fz = action[0] * force_limit, action[1] * force_limit, action[2] * force_limit
    torque = None
    if len(action) == 6:
        sx, sy, sz = torque_scale
        bx, by, bz = rotate_back(orientation, (action[3], action[4], action[5]))
        torque = rotate(orientation, (bx * sx, by * sy, bz * sz))
    gx, gy, gz = gravity
    ax, ay, az = fx / mass + gx, fy / mass + gy, fz / mass + gz
    x0, y0, z0 = position
    vx, vy, vz = velocity
    path = [
        (x0 + kh * vx + c * ax, y0 + kh * vy + c * ay, z0 + kh * vz + c * az) for kh, c in coef
    ]
    return (fx, fy, fz), torque, path


class Actuation:
    """The action scaling of one scenario (see the env's docstring, "Action space").

    ``torque_scale`` is ``torque_limit * I / max(I)`` per body (one row per body).
    """

    def __init__(
        self,
        scenario: Scenario,
        inertia: np.ndarray,
        uids: Sequence[int],
        *,
        use_torque: bool,
        substeps: int,
        sim_frequency: int,
    ) -> None:
        bodies = scenario.bodies
        self.use_torque = use_torque
        self.n_bodies = len(bodies)
        self._uids = list(uids)
        self._mass = [b.mass for b in bodies]
        self._inertia = inertia
        self._flimit = [float(b.force_limit) for b in bodies]
        self.torque_scale = np.array(
            [float(b.torque_limit) * row / row.max()
             for b, row in zip(bodies, inertia, strict=True)]
        )  # fmt: skip
        self._tscale = [tuple(row) for row in self.torque_scale.tolist()]
        self._gravity = tuple(float(g) for g in scenario.gravity)
        h = 1.0 / sim_frequency
        self._coef = [(k * h, h * h * k * (k + 1) / 2) for k in range(substeps)]
        self._zeros3n = [0.0] * (3 * self.n_bodies)
        self.idle = [0.0] * (6 * self.n_bodies)
        """The applied wrench record before any step (forces then torques, zeros)."""

    def drives(
        self, values: Sequence[float], states: Sequence[BodyReading]
    ) -> tuple[list[Drive], list[float]]:
        """The drives of one control period and the applied forces then torques (flat)."""
        use_torque = self.use_torque
        per = 6 if use_torque else 3
        gravity, coef = self._gravity, self._coef
        drives: list[Drive] = []
        applied_f: list[float] = []
        applied_t: list[float] = []
        for i, (pos, orn, lin, _) in enumerate(states):
            o = i * per
            f, tq, path = body_drive(
                values[o : o + per], pos, orn, lin, self._flimit[i], self._tscale[i],
                self._mass[i], gravity, coef,
            )  # fmt: skip
            applied_f += f
            if tq is not None:
                applied_t += tq
            drives.append((self._uids[i], f, tq, path))
        return drives, applied_f + (applied_t or self._zeros3n)

    def impulse(
        self, i: int, state: BodyReading, linear: np.ndarray, angular: np.ndarray
    ) -> tuple[list[float], list[float]]:
        """Body ``i``'s velocities after an impulse (N s) and angular impulse (N m s, world
        frame, about the centre of mass): ``v + p / m``, ``w + R I^-1 R^T L``."""
        _, orn, lin, ang = state
        rm = Simulator.rotation_matrix(orn)
        inverse_inertia = rm @ np.diag(1.0 / self._inertia[i]) @ rm.T
        new_lin = np.asarray(lin) + linear / self._mass[i]
        new_ang = np.asarray(ang) + inverse_inertia @ angular
        return new_lin.tolist(), new_ang.tolist()
