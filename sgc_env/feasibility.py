"""Feasibility of a resolved scenario: what the analytic SGC plan asks of each body.

The plan (``sgc_env.paper.plan``) is sampled on the control grid; the peak force ``m (a - g)``
and the peak torque ``I alpha + omega x (I omega)`` (world-frame inertia from the shape, as
PyBullet computes it) are compared with the body's ``force_limit`` and ``torque_limit``, the
planned centre of mass with the workspace, and the planned speeds with PyBullet's clamps. The
planner (and scipy) load only when a check runs, so ``import sgc_env`` stays light.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, cast

import numpy as np

from sgc_env.paper import quaternion as quat

if TYPE_CHECKING:
    from sgc_env.scenario import Body, Scenario

__all__ = ["BodyDemand", "body_demand", "body_demands", "inertia_diagonal", "inertia_bound"]

MAX_DEMAND_PERIODS = 600  # a plan sample costs ~0.3 ms: at most ~0.4 s per body


@dataclass(frozen=True)
class BodyDemand:
    """Peaks along one body's plan and the times they occur (seconds)."""

    force: float
    force_time: float
    torque: float
    torque_time: float
    speed: float
    speed_time: float
    spin: float
    spin_time: float
    outside_time: float | None  # first sample whose centre of mass leaves the workspace


def inertia_diagonal(shape: str, size: tuple[float, ...], mass: float) -> np.ndarray:
    """Principal moments (body frame) of a solid sphere, cylinder along z, or box."""
    if shape == "sphere":
        return np.full(3, 0.4 * mass * size[0] ** 2)
    if shape == "rod":
        length, r = size
        side = mass * (3 * r * r + length * length) / 12.0
        return np.array([side, side, 0.5 * mass * r * r])
    x, y, z = (2.0 * h for h in size)
    return mass / 12.0 * np.array([y * y + z * z, x * x + z * z, x * x + y * y])


def inertia_bound(shape: str, size: tuple[float, ...], mass: float) -> float:
    """Largest principal moment."""
    return float(inertia_diagonal(shape, size, mass).max())


def _plan(b: Body, control_frequency: int):
    """The body's plan, with somersault sub-courses timed on the env's ticks."""
    from sgc_env.paper.plan import BodyState, OrientationGoal, PlanOptions, PositionGoal, plan_body

    def vec(v):
        return None if v is None else np.asarray(v, float)

    return plan_body(
        BodyState(
            vec(b.position), vec(b.orientation), vec(b.linear_velocity), vec(b.angular_velocity)
        ),
        [
            PositionGoal(cast(float, g.time), vec(g.nail), vec(g.point))  # resolved: timed
            for g in b.goals
            if g.has_position
        ],
        [
            OrientationGoal(cast(float, g.time), vec(g.orientation), vec(g.relative_rotation))
            for g in b.goals
            if g.has_orientation
        ],
        end_velocity=vec(b.end_velocity),
        end_angular_velocity=vec(b.end_angular_velocity),
        options=PlanOptions(control_frequency=control_frequency),
    )


def _periods(ticks: int, goal_ticks: list[int], budget: int) -> list[int]:
    """Control periods (index k: from tick k to k + 1) to examine: all when few, else the
    two around every goal tick (where a course's acceleration peaks) and an even spread."""
    if ticks <= budget:
        return list(range(ticks))
    near = {k + d for k in goal_ticks for d in (-2, -1, 0) if 0 <= k + d < ticks}
    spread = np.linspace(0, ticks - 1, max(budget - len(near), 2)).round().astype(int)
    return sorted(near | set(spread.tolist()))


def body_demands(scenario: Scenario, periods: int | None = None) -> list[BodyDemand]:
    """:func:`body_demand` of every body."""
    return [body_demand(scenario, b, periods) for b in scenario.bodies]


def body_demand(scenario: Scenario, b: Body, periods: int | None = None) -> BodyDemand:
    """Peak demands of body ``b`` of a resolved scenario, per control period up to its last goal.

    A zero-order hold applies one force and torque per period, so the demand is the average
    over a period: ``|m (v(t+dt) - v(t)) / dt - m g|`` and the torque ``(L(t+dt) - L(t)) / dt``
    (world angular momentum ``L = R I R^T omega``) taken in the body axes as the env's action
    is, each axis weighted by ``max(I) / I`` (the env's per-axis torque scale), largest axis;
    the instantaneous peak at the end of a course is higher but lasts a fraction of a period.
    ``periods`` caps how many periods are examined (default ``MAX_DEMAND_PERIODS``; the ones
    around goal ticks always are). Raises ValueError where the planner cannot plan the goals.
    """
    g = np.asarray(scenario.gravity, float)
    low, high = (np.asarray(w, float) for w in scenario.workspace)
    freq = scenario.control_frequency
    dt = 1.0 / freq
    plan = _plan(b, freq)
    moments = inertia_diagonal(b.shape, b.size, b.mass)
    inertia = np.diag(moments)
    # The env scales each body axis' torque by I / max(I) (an action of 1 gives the same
    # angular acceleration about every axis), so a torque about the axis of least inertia
    # counts max(I) / I times against torque_limit.
    axis_weight = moments.max() / moments
    goal_ticks = [round(float(gl.time) * freq) for gl in b.goals]  # type: ignore[arg-type]
    cache: dict[int, tuple[np.ndarray, ...]] = {}

    def state(k: int) -> tuple[np.ndarray, ...]:
        if k not in cache:
            s = plan.sample(k * dt)
            rm = np.asarray(quat.to_matrix(s.orientation), float)
            momentum = rm @ inertia @ rm.T @ s.angular_velocity
            cache[k] = (s.position, s.velocity, s.angular_velocity, momentum, rm)
        return cache[k]

    peaks = dict.fromkeys(("force", "torque", "speed", "spin"), (0.0, 0.0))
    outside = None
    for k in _periods(max(goal_ticks), goal_ticks, periods or MAX_DEMAND_PERIODS):
        x0, v0, w0, l0, r0 = state(k)
        x1, v1, w1, l1, _ = state(k + 1)
        t = (k + 1) * dt
        body_torque = r0.T @ ((l1 - l0) / dt)  # in the body axes at the period's start
        values = {
            "force": b.mass * float(np.linalg.norm((v1 - v0) / dt - g)),
            "torque": float(np.max(np.abs(body_torque) * axis_weight)),
            "speed": float(max(np.linalg.norm(v0), np.linalg.norm(v1))),
            "spin": float(max(np.linalg.norm(w0), np.linalg.norm(w1))),
        }
        for key, value in values.items():
            if value > peaks[key][0]:
                peaks[key] = (value, t)
        if outside is None and not (np.all(low < x1) and np.all(x1 < high)):
            outside = t
    return BodyDemand(*peaks["force"], *peaks["torque"], *peaks["speed"], *peaks["spin"], outside)
