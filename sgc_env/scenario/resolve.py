"""Resolution: every goal gets a time on the control grid (non-critical times from the routing
weights of ``sgc_env.paper.routing``), nails bound to props are computed from the prop's path,
and the analytic plan is checked against the limits (:mod:`sgc_env.scenario.demand`).
``allow_saturation: true`` opts out of the force and torque part of that check.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace

import numpy as np

from sgc_env.paper import quaternion as quat
from sgc_env.paper.routing import resolve_goal_times
from sgc_env.scenario.demand import check_plan as _check_plan
from sgc_env.scenario.fields import MAX_EPISODE_STEPS, fail
from sgc_env.scenario.model import Body, Goal, Scenario, goal_orientations, grid_tick, grid_time
from sgc_env.scenario.validate import check_inside, validate_structure

__all__ = ["resolve_scenario"]

_TICK_TOL = 1e-9

# ---------------------------------------------------------------- resolution


def _rotation_angle(qa: Sequence[float], qb: Sequence[float]) -> float:
    dot = abs(float(np.dot(qa, qb)))
    return 2.0 * math.acos(min(1.0, dot))


def _on_grid(t: float, freq: int, mode: str, path: str) -> float:
    ticks = t * freq
    k = round(ticks)
    if abs(ticks - k) <= _TICK_TOL * max(1.0, abs(ticks)):
        return k / freq
    if mode == "snap":
        k = max(k, 1)
        return k / freq
    lo, hi = math.floor(ticks) / freq, math.ceil(ticks) / freq
    raise fail(
        path,
        f"{t} is not on the control grid (1/{freq} s); nearest ticks are {lo:.10g} and "
        f"{hi:.10g} (set time_grid: snap to round)",
    )


def _body_goal_times(b: Body, s: Scenario, freq: int, mode: str, p: str) -> list[float]:
    """Critical times on the grid, then routed non-critical times snapped to the grid."""
    times: list[float | None] = []
    critical: list[bool] = []
    distances: list[float] = []
    weights: list[float] = []
    prev_point: np.ndarray | None = None
    prev_q = b.orientation
    targets = goal_orientations(b)
    for j, g in enumerate(b.goals):
        gp = f"{p}.goals[{j}]"
        crit = g.is_critical
        if crit:
            if g.time is None:
                raise fail(f"{gp}.time", "a time-critical goal needs a time")
            times.append(_on_grid(float(g.time), freq, mode, f"{gp}.time"))
        else:
            if g.time is not None and not s.resolved:
                raise fail(
                    f"{gp}.time",
                    f"has time {g.time} but is not time-critical; "
                    "drop the time or mark it critical",
                )
            times.append(None)
        critical.append(crit)
        weights.append(float(g.weight))
        dist = 0.0
        if g.has_position:
            nail = _goal_nail(g, s, times[-1])
            if prev_point is None:
                prev_point = np.asarray(b.position, float) + quat.rotate(b.orientation, g.point)
            dist = float(np.linalg.norm(nail - prev_point)) if nail is not None else 0.0
            prev_point = nail
        q = targets[j]
        if q is not None:
            if g.relative_rotation is not None:
                angle = float(np.linalg.norm(g.relative_rotation))
            else:
                angle = _rotation_angle(prev_q, q)
            prev_q = q
            if not g.has_position:
                dist = angle
        distances.append(dist)
    for j in range(1, len(times)):
        if critical[j]:
            prev = [t for t in times[:j] if t is not None]
            if prev and times[j] <= prev[-1]:  # type: ignore[operator]
                raise fail(
                    f"{p}.goals[{j}].time",
                    f"{times[j]} is not after the previous goal time {prev[-1]}",
                )
    try:
        resolved = resolve_goal_times(times, critical, distances, weights, start_time=0.0)
    except ValueError as exc:
        raise fail(f"{p}.goals", str(exc)) from None
    out: list[float] = []
    last = 0.0
    for j, t in enumerate(resolved):
        t = grid_time(float(t), freq)
        if t <= last:
            raise fail(
                f"{p}.goals[{j}].time",
                f"routed time lands on tick {t:.10g}, not after the previous goal ({last:.10g}); "
                "use fewer goals, more time or a higher control_frequency",
            )
        out.append(t)
        last = t
    return out


def _goal_nail(g: Goal, s: Scenario, t: float | None) -> np.ndarray | None:
    if g.nail_prop is not None and t is not None:
        prop = next(pr for pr in s.props if pr.name == g.nail_prop)
        return prop.position_at(t)
    if g.nail is not None:
        return np.asarray(g.nail, float)
    return None


def resolve_scenario(
    scenario: Scenario,
    *,
    control_frequency: int | None = None,
    time_grid: str | None = None,
    check_plan: bool = True,
) -> Scenario:
    """Validate ``scenario`` and fill in every goal time (on the control grid) and prop nail.

    ``control_frequency``/``time_grid`` override the scenario's. Idempotent on a resolved
    scenario (non-critical times are re-routed from the critical ones). ``check_plan``: check
    the analytic plan against the limits (see :func:`_check_plan`); callers with a cheaper
    guarantee of their own (``random_scenarios``) turn it off.
    """
    s = scenario
    if control_frequency is not None:
        s = replace(s, control_frequency=control_frequency)
    if time_grid is not None:
        s = replace(s, time_grid=time_grid)
    validate_structure(s)
    bodies = []
    for i, b in enumerate(s.bodies):
        p = f"bodies[{i}]"
        times = _body_goal_times(b, s, s.control_frequency, s.time_grid, p)
        goals: list[Goal] = []
        for g, t in zip(b.goals, times, strict=True):
            nail = g.nail
            if g.nail_prop is not None:
                pos = _goal_nail(g, s, t)
                nail = tuple(float(x) for x in pos)  # type: ignore[union-attr,assignment]
                check_inside(nail, s.workspace, f"{p}.goals[{len(goals)}].nail")  # type: ignore[arg-type]
            goals.append(replace(g, time=t, critical=g.is_critical, nail=nail))
        bodies.append(replace(b, goals=tuple(goals)))
    out = replace(s, bodies=tuple(bodies), resolved=True)
    last = max(grid_tick(float(g.time), s.control_frequency) for b in bodies for g in b.goals)  # type: ignore[arg-type]
    steps = last + math.ceil(s.margin * s.control_frequency - 1e-9)
    if steps > MAX_EPISODE_STEPS:
        raise fail(
            "goals",
            f"the episode would last {steps} control ticks (last goal at {last} ticks plus the "
            f"margin); at most {MAX_EPISODE_STEPS}: use shorter goal times or a lower "
            "control_frequency",
        )
    if check_plan:
        _check_plan(out)
    return out
