"""What a model-based policy knows about an environment besides its observations.

Masses, inertias, action limits, gravity and the integrator's step are fixed by the scenario
and the env's construction; they are not in the observation because they never change within
an episode. A policy built from an :class:`EnvModel` stays a function of the observation.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from baselines.common.sub_envs import base_env
from sgc_env.observation import ObservationLayout
from sgc_env.paper import quaternion as quat
from sgc_env.paper.end_rules import DEFAULT_END_RULE

__all__ = ["BodyModel", "EnvModel"]


@dataclass(frozen=True)
class BodyModel:
    """Rigid-body constants of one driven body."""

    mass: float
    inertia: tuple[float, float, float]
    force_limit: float
    torque_limit: float
    torque_scale: tuple[float, float, float] = (1.0, 1.0, 1.0)
    """N m per unit of torque action along each principal axis (``env.torque_scale``)."""


@dataclass(frozen=True)
class EnvModel:
    """Static description of an SGC environment: enough to turn wrenches into actions."""

    layout: ObservationLayout
    bodies: tuple[BodyModel, ...]
    gravity: tuple[float, float, float]
    sim_dt: float
    substeps: int
    use_torque: bool
    end_rule: str = DEFAULT_END_RULE
    """The scenario's ``end_velocity_rule``: how a planner ends an interior course."""

    @property
    def control_dt(self) -> float:
        return self.sim_dt * self.substeps

    @classmethod
    def from_env(cls, env: Any) -> EnvModel:
        """Read the model of a Gymnasium env (wrapped or not) or of a vector env's first env."""
        base = base_env(env)
        scenario = base.scenario
        bodies = tuple(
            BodyModel(
                mass=float(b.mass),
                inertia=tuple(float(x) for x in inertia),  # type: ignore[arg-type]
                force_limit=float(b.force_limit),
                torque_limit=float(b.torque_limit),
                torque_scale=tuple(float(x) for x in scale),  # type: ignore[arg-type]
            )
            for b, inertia, scale in zip(
                scenario.bodies, base.body_inertia, base.torque_scale, strict=True
            )
        )
        return cls(
            layout=base.layout,
            bodies=bodies,
            gravity=tuple(float(g) for g in scenario.gravity),  # type: ignore[arg-type]
            sim_dt=1.0 / float(base.sim_frequency),
            substeps=int(base.substeps),
            use_torque=bool(base.use_torque),
            end_rule=scenario.end_velocity_rule,
        )

    def action_from_wrenches(self, forces, torques, orientations) -> np.ndarray:
        """Normalised, clipped action from world forces (N) and torques (N m), one per body.

        ``forces`` and ``torques``: arrays of shape (n, 3) or sequences of 3-tuples (the
        expert passes tuples; plain floats keep its control step cheap). ``orientations``:
        each body's quaternion (xyzw) at the start of the step, with which the env scales the
        torque action per principal axis (``tau = R0 diag(torque_scale) R0^T a``); here the
        inverse, ``a = R0 diag(1 / torque_scale) R0^T tau``, so the env applies ``tau``. The
        action is float64 on purpose: the env uses whatever precision it is given, and rounding
        the torque to the float32 of the action space moved a thin rod's orientation at a goal
        by up to ~1e-9 rad under unscaled world-frame torques.
        """
        n = len(self.bodies)
        if isinstance(forces, np.ndarray):
            forces = forces.reshape(n, 3).tolist()
        if isinstance(torques, np.ndarray):
            torques = torques.reshape(n, 3).tolist()
        if isinstance(orientations, np.ndarray):
            orientations = orientations.reshape(n, 4).tolist()
        out: list[float] = []
        use_torque = self.use_torque
        for body, force, torque, q in zip(self.bodies, forces, torques, orientations, strict=True):
            f_lim = body.force_limit
            out += (force[0] / f_lim, force[1] / f_lim, force[2] / f_lim)
            if use_torque:
                sx, sy, sz = body.torque_scale
                bx, by, bz = quat.rotate_back(q, torque)
                out += quat.rotate(q, (bx / sx, by / sy, bz / sz))
        return np.array([-1.0 if x < -1.0 else 1.0 if x > 1.0 else x for x in out])

