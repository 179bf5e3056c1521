"""Scorecards: exactness, punctuality, smoothness, effort and success of one rollout.

`score_body` scores one body's sampled trajectory against its goals; `score_episode` builds
the trajectories from rollout infos and aggregates over bodies. Definitions, units and
defaults are in docs/metrics.md.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

from sgc_env.metrics import signals as sg
from sgc_env.metrics.trajectory import BodyTrajectory, GoalSpec, Tolerances

#: SPARC cutoff in cycles per course duration: 10 Hz for a 1 s course, the reference default.
SPARC_CYCLES_PER_COURSE = 10.0
#: A speed minimum counts when its prominence exceeds this share of the course's peak speed.
MINIMA_RELATIVE_PROMINENCE = 0.1
#: Fewest samples in a course for SPARC and LDLJ (fewer gives nan).
MIN_COURSE_SAMPLES = 4
#: Peak speed (m/s or rad/s) below which a course counts as still: SPARC, LDLJ and minima of
#: float noise mean nothing, so they are nan (minima 0).
STILL_SPEED = 1e-6


def _check_goals(goals: Sequence[GoalSpec], start_time: float) -> None:
    if len(goals) == 0:
        raise ValueError("goals must not be empty")
    times = [g.time for g in goals]
    if np.any(np.diff(times) <= 0.0):
        raise ValueError(
            "goals must have strictly increasing times (merge a nail and an orientation "
            "that share a time into one GoalSpec)"
        )
    if times[0] <= start_time:
        raise ValueError(f"the first goal time ({times[0]}) must exceed start_time ({start_time})")


def _windows(times: Sequence[float], start_time: float) -> list[tuple[float, float]]:
    """[t_i - T_i/2, t_i + T_{i+1}/2] per goal of one track; the last one mirrors T_i."""
    out = []
    for i, t in enumerate(times):
        before = t - (times[i - 1] if i > 0 else start_time)
        after = times[i + 1] - t if i + 1 < len(times) else before
        out.append((t - before / 2.0, t + after / 2.0))
    return out


def _after_end(traj: BodyTrajectory, goal: GoalSpec) -> bool:
    """The rollout ended (terminated or cut) before the goal's time."""
    return goal.time > traj.times[-1] + sg.TIME_SLACK


def _position_goal_metrics(
    traj: BodyTrajectory,
    goals: list[GoalSpec],
    start_time: float,
    tol: Tolerances,
) -> list[dict[str, float]]:
    out = []
    windows = _windows([g.time for g in goals], start_time)
    previous_nail: np.ndarray | None = None
    previous_time = start_time
    for goal, (lo, hi) in zip(goals, windows, strict=True):
        nail = np.asarray(goal.nail, dtype=float)
        pos, vel = traj.tracked_point(goal.point)
        dist = np.linalg.norm(pos - nail, axis=1)
        error = float(np.linalg.norm(sg.interpolate_at(traj.times, pos, goal.time) - nail))
        speed = float(np.linalg.norm(sg.interpolate_at(traj.times, vel, goal.time)))
        if _after_end(traj, goal):
            error = speed = math.nan
        t_close, d_close = sg.closest_approach(traj.times, pos - nail, lo, hi)
        t_entry = sg.first_entry(traj.times, dist, tol.position, lo, hi)
        start = (
            sg.interpolate_at(traj.times, pos, previous_time)
            if previous_nail is None
            else previous_nail
        )
        average_speed = float(np.linalg.norm(nail - start)) / (goal.time - previous_time)
        out.append(
            {
                "time": goal.time,
                "position_error": error,
                "closest_time": t_close,
                "closest_offset": t_close - goal.time,
                "closest_distance": d_close,
                "entry_offset": t_entry - goal.time,
                "velocity_jump": sg.velocity_jump(traj.times, vel, goal.time),
                "speed": speed,
                "goal_speed_ratio": speed / average_speed if average_speed > 0.0 else math.nan,
            }
        )
        previous_nail, previous_time = nail, goal.time
    return out


def _closest_orientation(
    traj: BodyTrajectory, target: Sequence[float], angle: np.ndarray, lo: float, hi: float
) -> tuple[float, float]:
    """Closest approach to an orientation goal, refined on the rotation-vector segments.

    The segments next to the best tick are used as for positions (exact at a hit on a tick
    whatever the angular speeds around it), but only where that tick is within pi/2 of the
    goal: principal rotation vectors jump near pi, and a segment across the jump would pass
    near the origin. Farther off, the angle's parabola refinement stands.
    """
    inside = sg.in_window(traj.times, lo, hi)
    if inside.size:
        k = int(inside[np.argmin(angle[inside])])
        if angle[k] < math.pi / 2:
            near = slice(max(k - 1, int(inside[0])), min(k + 2, int(inside[-1]) + 1))
            offsets = traj.orientation_offset(target, near)
            return sg.closest_approach(traj.times[near], offsets, lo, hi)
    return sg.closest_approach(traj.times, angle, lo, hi)


def _orientation_goal_metrics(
    traj: BodyTrajectory, goals: list[GoalSpec], start_time: float, tol: Tolerances
) -> list[dict[str, float]]:
    out = []
    windows = _windows([g.time for g in goals], start_time)
    for goal, (lo, hi) in zip(goals, windows, strict=True):
        if goal.orientation is None:
            raise ValueError(f"goal at t={goal.time}: orientation metrics need an orientation")
        target = Rotation.from_quat(np.asarray(goal.orientation, dtype=float))
        err = traj.orientation_error(goal.orientation)
        error = float((traj.orientation_at(goal.time) * target.inv()).magnitude())
        if _after_end(traj, goal):
            error = math.nan
        t_close, d_close = _closest_orientation(traj, goal.orientation, err, lo, hi)
        t_entry = sg.first_entry(traj.times, err, tol.orientation, lo, hi)
        out.append(
            {
                "time": goal.time,
                "orientation_error": error,
                "closest_time": t_close,
                "closest_offset": t_close - goal.time,
                "closest_angle": d_close,
                "entry_offset": t_entry - goal.time,
                "angular_velocity_jump": sg.velocity_jump(
                    traj.times, traj.body_angular_velocity, goal.time
                ),
            }
        )
    return out


def _goal_met(traj: BodyTrajectory, goal: GoalSpec, tol: Tolerances) -> bool:
    """Met iff every part is within tolerance at t_i (interpolated between ticks), or, with a
    time tolerance, at a tick within it of t_i."""
    if _after_end(traj, goal):
        return False
    ticks = sg.in_window(traj.times, goal.time - tol.time, goal.time + tol.time)
    ok_at_ticks = np.ones(ticks.size, dtype=bool)
    ok_at_goal = True
    if goal.nail is not None:
        nail = np.asarray(goal.nail, dtype=float)
        pos, _ = traj.tracked_point(goal.point)
        ok_at_ticks &= np.linalg.norm(pos[ticks] - nail, axis=1) <= tol.position
        at_goal = sg.interpolate_at(traj.times, pos, goal.time)
        ok_at_goal &= bool(np.linalg.norm(at_goal - nail) <= tol.position)
    if goal.orientation is not None:
        ok_at_ticks &= traj.orientation_error(goal.orientation)[ticks] <= tol.orientation
        target = Rotation.from_quat(np.asarray(goal.orientation, dtype=float))
        angle = (traj.orientation_at(goal.time) * target.inv()).magnitude()
        ok_at_goal &= bool(angle <= tol.orientation)
    return bool(ok_at_goal or np.any(ok_at_ticks))


def _position_courses(
    traj: BodyTrajectory,
    goals: Sequence[GoalSpec],
    start_time: float,
    sparc_cycles: float,
    minima_prominence: float,
) -> list[dict[str, float]]:
    """Smoothness of the tracked point per course of the position track."""
    fs = 1.0 / traj.dt
    out = []
    previous = start_time
    for i, goal in enumerate(goals):
        duration = goal.time - previous
        idx = sg.in_window(traj.times, previous, goal.time)
        _, vel = traj.tracked_point(goal.point)
        speed = np.linalg.norm(vel, axis=1)
        fc = min(sparc_cycles / duration, fs / 2.0)
        moving = idx.size >= MIN_COURSE_SAMPLES and float(speed[idx].max()) > STILL_SPEED
        minima = 0
        if moving:
            found = sg.speed_minima(speed, minima_prominence * float(speed[idx].max()))
            # A stop at the last goal is the scenario's choice (its end velocity), not a fault.
            last = i == len(goals) - 1
            end = goal.time - traj.dt / 2.0 if last else goal.time + sg.TIME_SLACK
            at = traj.times[found]
            minima = int(np.sum((at > previous + sg.TIME_SLACK) & (at <= end)))
        out.append(
            {
                "start": previous,
                "end": goal.time,
                "duration": duration,
                "samples": int(idx.size),
                "sparc": sg.sparc(speed[idx], fs, fc=fc) if moving else math.nan,
                "sparc_cutoff_hz": fc,
                "ldlj": sg.ldlj(vel[idx], traj.dt) if moving else math.nan,
                "speed_minima": minima,
            }
        )
        previous = goal.time
    return out


def _rotation_courses(
    traj: BodyTrajectory,
    goals: Sequence[GoalSpec],
    start_time: float,
    tol: Tolerances,
    sparc_cycles: float,
) -> list[dict[str, float]]:
    """Rotation per course of the orientation track (of all goals if there is none)."""
    fs = 1.0 / traj.dt
    omega = np.linalg.norm(traj.body_angular_velocity, axis=1)
    out = []
    previous = start_time
    for goal in goals:
        duration = goal.time - previous
        idx = sg.in_window(traj.times, previous, goal.time)
        fc = min(sparc_cycles / duration, fs / 2.0)
        moving = idx.size >= MIN_COURSE_SAMPLES and float(omega[idx].max()) > STILL_SPEED
        weights = sg.step_weights(traj.times, traj.dt, previous, goal.time)
        travelled = sg.angle_travelled(traj.body_angular_velocity, weights)
        if goal.rotation_angle is not None:
            needed = goal.rotation_angle
        else:
            needed = float(
                (traj.orientation_at(goal.time) * traj.orientation_at(previous).inv()).magnitude()
            )
        out.append(
            {
                "start": previous,
                "end": goal.time,
                "duration": duration,
                "samples": int(idx.size),
                "angular_sparc": sg.sparc(omega[idx], fs, fc=fc) if moving else math.nan,
                "angular_ldlj": (
                    sg.ldlj(traj.body_angular_velocity[idx], traj.dt) if moving else math.nan
                ),
                "angle_travelled": travelled,
                "angle_needed": needed,
                "rotation_ratio": sg.rotation_ratio(travelled, needed, tol.orientation),
                "rotation_excess": max(travelled - needed, 0.0),
            }
        )
        previous = goal.time
    return out


def _track_smoothness(
    traj: BodyTrajectory, goals: Sequence[GoalSpec], start_time: float, sparc_cycles: float
) -> dict[str, float]:
    """SPARC of the whole movement from start_time to the last goal, tracked point speed.

    Per-course SPARC cannot see a stop at a goal (each course alone is a clean bell); over the
    whole track every stop adds a lobe. Cutoff: sparc_cycles per median course duration.
    nan without position goals or movement.
    """
    if not goals:
        return {"sparc_track": math.nan, "sparc_track_cutoff_hz": math.nan}
    idx = sg.in_window(traj.times, start_time, goals[-1].time)
    durations = np.diff([start_time, *[g.time for g in goals]])
    fs = 1.0 / traj.dt
    fc = min(sparc_cycles / float(np.median(durations)), fs / 2.0)
    _, vel = traj.tracked_point(goals[-1].point)
    speed = np.linalg.norm(vel[idx], axis=1)
    if idx.size < MIN_COURSE_SAMPLES or float(speed.max(initial=0.0)) <= STILL_SPEED:
        return {"sparc_track": math.nan, "sparc_track_cutoff_hz": fc}
    return {"sparc_track": sg.sparc(speed, fs, fc=fc), "sparc_track_cutoff_hz": fc}


def _track_kinematics(
    traj: BodyTrajectory,
    velocity: np.ndarray,
    goals: Sequence[GoalSpec],
    start_time: float,
    prefix: str,
) -> dict[str, float]:
    """LDLJ, peak acceleration and the largest one-tick change of acceleration over a track.

    Every tick from ``start_time`` to the track's last goal counts, so kinks at goals and at
    boundaries no goal marks (a split somersault's sub-courses) are all seen. nan without
    goals, movement or enough samples.
    """
    keys = (f"{prefix}ldlj_track", f"{prefix}acceleration_peak", f"{prefix}acceleration_kink")
    if not goals:
        return dict.fromkeys(keys, math.nan)
    idx = sg.in_window(traj.times, start_time, goals[-1].time)
    v = velocity[idx]
    if idx.size < MIN_COURSE_SAMPLES or float(np.linalg.norm(v, axis=1).max()) <= STILL_SPEED:
        return dict.fromkeys(keys, math.nan)
    peak, kink = sg.acceleration_peak_and_kink(v, traj.dt)
    return dict(zip(keys, (sg.ldlj(v, traj.dt), peak, kink), strict=True))


def _effort(traj: BodyTrajectory) -> dict[str, float]:
    weights = np.full(traj.times.size, traj.dt)
    return {
        "force_sq_integral": sg.integral_of_squares(traj.force, weights),
        "torque_sq_integral": sg.integral_of_squares(traj.torque, weights),
        "force_peak": float(np.max(np.linalg.norm(traj.force, axis=1))),
        "torque_peak": float(np.max(np.linalg.norm(traj.torque, axis=1))),
    }


def _safe_min(values: np.ndarray) -> float:
    finite = values[np.isfinite(values)]
    return float(finite.min()) if finite.size else math.nan


def _column(rows: Sequence[Mapping[str, Any]], key: str) -> np.ndarray:
    return np.array([row[key] for row in rows], dtype=float)


def score_body(
    trajectory: BodyTrajectory,
    goals: Sequence[GoalSpec],
    tolerances: Tolerances | None = None,
    *,
    start_time: float = 0.0,
    sparc_cycles: float = SPARC_CYCLES_PER_COURSE,
    minima_prominence: float = MINIMA_RELATIVE_PROMINENCE,
) -> dict[str, Any]:
    """Scorecard of one body: per-goal and per-course rows plus summary numbers.

    `goals` are in time order with strictly increasing times; course i runs from the previous
    goal (or `start_time`) to goal i. Summary keys are listed in docs/metrics.md.
    """
    tol = Tolerances() if tolerances is None else tolerances
    goals = list(goals)
    _check_goals(goals, start_time)
    if not (math.isfinite(sparc_cycles) and sparc_cycles > 0.0):
        raise ValueError(f"sparc_cycles must be finite and positive, got {sparc_cycles}")
    if not 0.0 <= minima_prominence < 1.0:
        raise ValueError(f"minima_prominence must lie in [0, 1), got {minima_prominence}")
    pos_goals = [g for g in goals if g.nail is not None]
    ori_goals = [g for g in goals if g.orientation is not None]
    pos_rows = _position_goal_metrics(trajectory, pos_goals, start_time, tol)
    ori_rows = _orientation_goal_metrics(trajectory, ori_goals, start_time, tol)
    pos_courses = _position_courses(
        trajectory, pos_goals, start_time, sparc_cycles, minima_prominence
    )
    rot_courses = _rotation_courses(trajectory, ori_goals or goals, start_time, tol, sparc_cycles)
    met = [_goal_met(trajectory, g, tol) for g in goals]
    card: dict[str, Any] = {
        "n_goals": len(goals),
        "goals_met": int(sum(met)),
        "goals_after_end": int(sum(_after_end(trajectory, g) for g in goals)),
        "success_rate": float(np.mean(met)),
        "met": met,
        "position_goals": pos_rows,
        "orientation_goals": ori_rows,
        "position_courses": pos_courses,
        "rotation_courses": rot_courses,
    }
    for prefix, rows, err_key in (
        ("position", pos_rows, "position_error"),
        ("orientation", ori_rows, "orientation_error"),
    ):
        err = _column(rows, err_key)
        card[f"{prefix}_error_max"] = sg.safe_max(err)
        card[f"{prefix}_error_mean"] = sg.safe_mean(err)
        card[f"{prefix}_closest_offset_abs_max"] = sg.safe_max(
            np.abs(_column(rows, "closest_offset"))
        )
        card[f"{prefix}_entry_offset_abs_max"] = sg.safe_max(np.abs(_column(rows, "entry_offset")))
    card["velocity_jump_max"] = sg.safe_max(_column(pos_rows, "velocity_jump"))
    card["angular_velocity_jump_max"] = sg.safe_max(_column(ori_rows, "angular_velocity_jump"))
    card["goal_speed_ratio_min"] = _safe_min(_column(pos_rows[:-1], "goal_speed_ratio"))
    card["sparc_mean"] = sg.safe_mean(_column(pos_courses, "sparc"))
    card["ldlj_mean"] = sg.safe_mean(_column(pos_courses, "ldlj"))
    card["speed_minima_total"] = int(np.sum(_column(pos_courses, "speed_minima")))
    card["angular_sparc_mean"] = sg.safe_mean(_column(rot_courses, "angular_sparc"))
    card["rotation_ratio_max"] = sg.safe_max(_column(rot_courses, "rotation_ratio"))
    card["rotation_excess_total"] = float(np.sum(_column(rot_courses, "rotation_excess")))
    card["angular_ldlj_mean"] = sg.safe_mean(_column(rot_courses, "angular_ldlj"))
    card.update(_track_smoothness(trajectory, pos_goals, start_time, sparc_cycles))
    point_velocity = (
        trajectory.tracked_point(pos_goals[-1].point)[1] if pos_goals else trajectory.body_velocity
    )
    card.update(_track_kinematics(trajectory, point_velocity, pos_goals, start_time, ""))
    card.update(
        _track_kinematics(
            trajectory, trajectory.body_angular_velocity, ori_goals or goals, start_time,
            "angular_",
        )
    )  # fmt: skip
    card.update(_effort(trajectory))
    return card


_EPISODE_MAX_KEYS = (
    "position_error_max",
    "orientation_error_max",
    "position_closest_offset_abs_max",
    "orientation_closest_offset_abs_max",
    "position_entry_offset_abs_max",
    "orientation_entry_offset_abs_max",
    "velocity_jump_max",
    "angular_velocity_jump_max",
    "rotation_ratio_max",
    "acceleration_peak",
    "acceleration_kink",
    "angular_acceleration_peak",
    "angular_acceleration_kink",
    "force_peak",
    "torque_peak",
)
_EPISODE_SUM_KEYS = (
    "n_goals",
    "goals_met",
    "goals_after_end",
    "speed_minima_total",
    "rotation_excess_total",
    "force_sq_integral",
    "torque_sq_integral",
)


def score_episode(
    infos: Sequence[Mapping[str, Any]],
    goals: Sequence[Sequence[GoalSpec]],
    dt: float,
    tolerances: Tolerances | None = None,
    initial_info: Mapping[str, Any] | None = None,
    **score_kwargs: Any,
) -> dict[str, Any]:
    """Score every body of a rollout; `goals[b]` are body b's goals (empty: body not scored).

    `initial_info` is the state before the first step (see `BodyTrajectory.from_infos`);
    `score_kwargs` go to `score_body`.

    Aggregates: sums of counts and effort, maxima of errors, offsets, jumps and peaks, the
    share of all goals met, and course-weighted means of SPARC and LDLJ.
    """
    if len(goals) == 0:
        raise ValueError("goals must list at least one body")
    bodies: list[dict[str, Any] | None] = []
    for b, body_goals in enumerate(goals):
        if len(body_goals) == 0:
            bodies.append(None)
            continue
        traj = BodyTrajectory.from_infos(infos, b, dt, initial_info)
        bodies.append(score_body(traj, body_goals, tolerances, **score_kwargs))
    cards = [c for c in bodies if c is not None]
    if not cards:
        raise ValueError("goals must give at least one body a goal")
    summary: dict[str, Any] = {"bodies": bodies}
    for key in _EPISODE_SUM_KEYS:
        summary[key] = sum(c[key] for c in cards)
    for key in _EPISODE_MAX_KEYS:
        summary[key] = sg.safe_max([c[key] for c in cards])
    summary["success_rate"] = summary["goals_met"] / summary["n_goals"]
    pos_courses = [row for c in cards for row in c["position_courses"]]
    rot_courses = [row for c in cards for row in c["rotation_courses"]]
    for key, rows in (("sparc", pos_courses), ("ldlj", pos_courses)):
        summary[f"{key}_mean"] = sg.safe_mean(_column(rows, key))
    summary["angular_sparc_mean"] = sg.safe_mean(_column(rot_courses, "angular_sparc"))
    summary["angular_ldlj_mean"] = sg.safe_mean(_column(rot_courses, "angular_ldlj"))
    for key in ("ldlj_track", "angular_ldlj_track"):
        summary[f"{key}_mean"] = sg.safe_mean([c[key] for c in cards])
    summary["sparc_track_mean"] = sg.safe_mean([c["sparc_track"] for c in cards])
    return summary
