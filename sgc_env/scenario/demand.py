"""What the analytic SGC plan asks of each body: the one plan-demand check of scenarios.

:func:`body_plan` builds the planner call once, with the scenario's ``end_velocity_rule`` (the
plan the expert flies). :func:`body_demand` samples it per control period: the peak force
``m (a - g)`` and the peak torque ``I alpha + omega x (I omega)`` (world-frame inertia from the
shape, as PyBullet computes it) against the body's ``force_limit`` and ``torque_limit``, the
planned centre of mass against the workspace and the planned speeds against PyBullet's clamps;
:func:`check_plan` turns that into ScenarioErrors for :func:`resolve_scenario`.
:func:`demand_bounds` is the cheaper, conservative bound of the same plan the random scene
families check on every draw. The planner (and scipy) load only when a check runs, so
``import sgc_env`` stays light.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import TYPE_CHECKING, cast

import numpy as np

from sgc_env.paper import quaternion as quat
from sgc_env.scenario.fields import LIMITS, fail
from sgc_env.scenario.model import Body, Scenario, grid_tick

if TYPE_CHECKING:
    from sgc_env.paper.plan import BodyPlan

__all__ = [
    "BodyDemand", "body_demand", "body_demands", "body_plan", "check_plan", "demand_bounds",
    "inertia_diagonal",
]  # fmt: skip

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


def body_plan(scenario: Scenario, b: Body) -> BodyPlan:
    """The plan the expert flies for body ``b`` of a resolved scenario: the scenario's
    ``end_velocity_rule``, somersault sub-courses timed on the env's ticks. The one place the
    planner is called from a scenario."""
    from sgc_env.paper.plan import BodyState, OrientationGoal, PlanOptions, PositionGoal, plan_body

    def vec(v: object) -> np.ndarray | None:
        return None if v is None else np.asarray(v, float)

    return plan_body(
        BodyState(
            np.asarray(b.position, float), np.asarray(b.orientation, float),
            np.asarray(b.linear_velocity, float), np.asarray(b.angular_velocity, float),
        ),
        [
            PositionGoal(cast(float, g.time), np.asarray(g.nail, float), np.asarray(g.point, float))
            for g in b.goals
            if g.has_position  # resolved: timed, nails of props filled in
        ],
        [
            OrientationGoal(cast(float, g.time), vec(g.orientation), vec(g.relative_rotation))
            for g in b.goals
            if g.has_orientation
        ],
        end_velocity=vec(b.end_velocity),
        end_angular_velocity=vec(b.end_angular_velocity),
        options=PlanOptions(
            control_frequency=scenario.control_frequency, end_rule=scenario.end_velocity_rule
        ),
    )  # fmt: skip


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
    plan = body_plan(scenario, b)
    moments = inertia_diagonal(b.shape, b.size, b.mass)
    inertia = np.diag(moments)
    # The env scales each body axis' torque by I / max(I) (an action of 1 gives the same
    # angular acceleration about every axis), so a torque about the axis of least inertia
    # counts max(I) / I times against torque_limit.
    axis_weight = moments.max() / moments
    goal_ticks = [grid_tick(float(gl.time), freq) for gl in b.goals]  # type: ignore[arg-type]
    cache: dict[int, tuple[np.ndarray, ...]] = {}

    def state(k: int) -> tuple[np.ndarray, ...]:
        if k not in cache:
            s = plan.sample(k * dt)
            rm = np.asarray(quat.to_matrix(s.orientation.tolist()), float)
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


def demand_bounds(scenario: Scenario, samples: int = 64) -> list[tuple[float, float]]:
    """Upper bounds of the peak |force| and |torque| per body along the analytic SGC plan.

    Sampled on every course of both tracks (``samples`` times each, both ends included), one
    vectorised evaluation per course (``BodyPlan.deviations``): a few milliseconds per body
    after planning, cheap enough for the random families to check every draw. With ``p''`` the
    tracked point's acceleration, ``r`` its largest offset from the centre of mass and ``phi``
    the orientation deviation (``omega = J_l(phi) phi'``, ``|J_l| <= 1``)::

        |omega| <= |phi'|,   |omega'| <= |phi''| + j(|phi|) |phi'|^2,   spin = |omega'| + |omega|^2
        force  <= m (|p'' - g| + r spin),   torque <= I_max spin   (gyroscopic term included)

    where ``j(theta) = (theta e^theta - e^theta + 1) / theta^2`` bounds the rate of ``J_l``
    (its series, term by term). Without an orientation track ``omega`` is the constant
    initial one. The torque action ``R0 diag(1 / torque_scale) R0^T tau`` has principal
    components ``(I_k alpha_k + gyro_k) / (torque_limit I_k / I_max)`` and
    ``|gyro_k| <= I_k |omega_j omega_l|`` (principal moments obey ``I_k >= |I_j - I_l|``), so its
    norm, and every entry, stays below ``torque / torque_limit``: a torque bound below
    ``torque_limit`` keeps the scaled torque action inside the box.
    """
    g = np.asarray(scenario.gravity, float)
    grid = np.linspace(1e-9, 1.0, samples)
    out = []
    for b in scenario.bodies:
        plan = body_plan(scenario, b)
        times = np.concatenate([c.t_start + (c.t_end - c.t_start) * grid for c in plan.courses])
        accel = plan.deviations(times, "position")[2]
        if b.has_orientation_track:
            phi, phi_dot, phi_ddot = plan.deviations(times, "orientation")
            w2 = np.sum(phi_dot**2, axis=1)
            theta = np.linalg.norm(phi, axis=1)
            spin = np.linalg.norm(phi_ddot, axis=1) + (_jacobian_rate(theta) + 1.0) * w2
        else:
            spin = np.full(times.shape, float(np.dot(b.angular_velocity, b.angular_velocity)))
        arm = max((float(np.linalg.norm(gl.point)) for gl in b.goals if gl.has_position), default=0)
        inertia = float(inertia_diagonal(b.shape, b.size, b.mass).max())
        force = b.mass * (np.linalg.norm(accel - g, axis=1) + arm * spin)
        out.append((float(force.max()), float(inertia * spin.max())))
    return out


def _jacobian_rate(theta: np.ndarray) -> np.ndarray:
    """``(theta e^theta - e^theta + 1) / theta^2``, its series ``1/2 + theta/3 + theta^2/8``
    below 1e-3."""
    small = theta < 1e-3
    t = np.where(small, 1.0, theta)
    exact = (t * np.exp(t) - np.exp(t) + 1.0) / (t * t)
    return np.where(small, 0.5 + theta / 3.0 + theta * theta / 8.0, exact)


def _goal_at(b: Body, t: float) -> int:
    """Index of the goal whose course contains time ``t`` (the first goal not before it)."""
    for j, g in enumerate(b.goals):
        if float(g.time) >= t - 1e-9:  # type: ignore[arg-type]
            return j
    return len(b.goals) - 1


@lru_cache(maxsize=64)
def check_plan(s: Scenario) -> None:
    """The analytic plan of the rule the expert flies (``s.end_velocity_rule``) against the
    limits, the workspace and the speed clamps (cached: scenarios are frozen and hashable)."""

    for i, b in enumerate(s.bodies):
        p = f"bodies[{i}]"
        try:
            d = body_demand(s, b)
        except ValueError as exc:  # goals the planner cannot plan (e.g. too few ticks)
            raise fail(f"{p}.goals", str(exc)) from None
        if d.outside_time is not None:
            raise fail(
                f"{p}.goals[{_goal_at(b, d.outside_time)}]",
                f"the planned path leaves the workspace at t = {d.outside_time:.4g} s; "
                "widen the workspace or move the goal",
            )
        for value, when, key, what in (
            (d.speed, d.speed_time, "speed", "a speed"), (d.spin, d.spin_time, "spin", "a spin")
        ):  # fmt: skip
            if value > LIMITS[key][1]:
                raise fail(
                    f"{p}.goals[{_goal_at(b, when)}]",
                    f"the plan needs {what} of {value:.4g} {LIMITS[key][2]} near t = "
                    f"{when:.4g} s, above {LIMITS[key][1]:g} ({LIMITS[key][3]}); give it more time",
                )
        if s.allow_saturation:
            continue
        for value, when, key, unit in (
            (d.force, d.force_time, "force_limit", "N"),
            (d.torque, d.torque_time, "torque_limit", "N m"),
        ):
            limit = float(getattr(b, key))
            if value > limit:
                raise fail(
                    f"{p}.goals[{_goal_at(b, when)}]",
                    f"the plan needs a peak {key[:-6]} of {value:.4g} {unit} near t = "
                    f"{when:.4g} s, above {p}.{key} = {limit:g} {unit}; raise the limit, give "
                    "the goal more time, or set allow_saturation: true to accept saturation",
                )
