"""The analytic expert: the paper's sequential-goal controller as a stateless policy.

Every control step the expert re-plans the rest of the current course from the measured state
(the SGC family is time-consistent, so with nothing disturbing the body this *is* the plan
made at the course start) and then chooses the force and torque that land the body exactly on
the plan's next sample, through the known PyBullet integrator
(:mod:`baselines.controllers.tracking`). On the tick that reaches a goal the next sample is the goal
itself, so goals are met to floating point. A push mid-course simply becomes a new measured state to
re-plan from.

On an env of the planner's view the policy reads only the observation (plus the env's
constants in :class:`EnvModel`), so it runs inside ``evaluate_policy``, vector envs and
imitation tools, offline observations included. Built on an env of another view (the
learner's view every id observes) it acts on the env's planner view of its current state
(:func:`~baselines.common.planner_view.planner_reader`): it must then be asked about the
observation that env just returned, which it checks.
"""

from __future__ import annotations

import bisect
import math
from typing import Any

import numpy as np

from baselines.common.env_model import BodyModel, EnvModel
from baselines.common.observation_fields import COURSE_SIZE, BodyFields, TrackFields
from baselines.common.planner_view import PlannerReader, planner_input, planner_reader
from baselines.common.sub_envs import base_env
from baselines.controllers.actuation import body_wrench
from baselines.controllers.matched_table import (
    EXPERT_RULES,
    MatchedTable,
    course_key,
    matched_table,
)
from baselines.controllers.smooth_table import SmoothCourse, SmoothTable, smooth_table
from sgc_env.paper import quaternion as quat
from sgc_env.paper.frames import course_end_velocity, next_deviation
from sgc_env.paper.orientation import left_jacobian_inverse_apply

__all__ = ["SGCExpert"]

GOAL_TICK_SLACK = 1e-6
"""A goal is on the next tick when its time left is within this relative slack of one period."""

_CACHE_SIZE = 64
"""Courses whose end velocity and frame are memoised (they are constant over a course)."""

_ZERO3 = (0.0, 0.0, 0.0)
_IDENTITY_ROWS = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))


class SGCExpert:
    """Sequential-goal constraints expert with an SB3-style ``predict``.

    Build it from the environment it will drive (``SGCExpert(env)``, wrapped or vectorised
    envs too): it needs the bodies' masses, inertias and action limits, which are constants of
    the env rather than observations. On an env that observes another view than the
    planner's, ``predict`` reads the planner's view of that env's current state and must be
    handed the observation the env just returned (a ValueError otherwise:
    :class:`~baselines.common.planner_view.PlannerReader`); goals stay exact.
    """

    def __init__(
        self,
        env: Any | None = None,
        *,
        model: EnvModel | None = None,
        refine: bool = True,
        end_rule: str | None = None,
        scenario: Any | None = None,
    ) -> None:
        """``end_rule``: how interior courses end, ``"tangent"`` or ``"paper"`` (eqs. 12-14,
        :mod:`sgc_env.paper.frames`), ``"matched"`` (:mod:`sgc_env.paper.matched`:
        accelerations matched over whole tracks) or ``"smooth"`` (SGC sub-courses between
        transient sub-goals on the minimum-jerk reference,
        :mod:`baselines.controllers.smooth_table`); None follows the scenario (``model.end_rule``).
        ``"matched"`` and ``"smooth"`` read the episode's scenario (``scenario``, else ``env``'s
        current one, re-read when a course is not found) and look every course up in their table
        (:mod:`baselines.controllers.matched_table`,
        :mod:`baselines.controllers.smooth_table`); a course they do not know (a state of another
        scenario) ends by the tangent rule.

        ``refine``: give the torque between goals its correction step on the simulated
        rotation (goal ticks, and every tick under ``"smooth"``, get the exact Newton).

        Measured on SGCRod-v1 and the three-rod demo: the closed-form first guess alone
        misses the planned rotation by ~1e-6 rad per tick (median; up to 1e-4 on a thin rod's
        somersault, whose tiny axial inertia makes the torque's effect depend on the path the
        axis takes), the corrected torque by ~1e-8 (up to 1e-5). Re-planning every tick
        absorbs either and goals stay exact to ~1e-14, but without the correction the path
        drifts from the exactly tracked one by up to 3e-3 (rad or m) instead of 1e-4. The
        correction costs about 8 us per body and step (``scripts/bench_expert.py``).
        """
        if model is None:
            if env is None:
                raise ValueError("SGCExpert needs an env or an EnvModel")
            model = EnvModel.from_env(env)
        if end_rule is not None and end_rule not in EXPERT_RULES:
            raise ValueError(f"end_rule must be one of {list(EXPERT_RULES)}, got {end_rule!r}")
        if end_rule in ("matched", "smooth") and env is None and scenario is None:
            raise ValueError(f"end_rule={end_rule!r} needs the env or the episode's scenario")
        self.model = model
        self._env = env
        self._planner: PlannerReader | None = None
        if env is not None:  # None on the planner's view: the observation is read as it is
            self._planner = planner_reader(env, "SGCExpert")
        self._scenario = scenario
        self._table: MatchedTable | None = None
        self.refine = refine
        self.end_rule = end_rule
        self._fields_of: EnvModel | None = None  # the model ``_bodies`` was built for
        self._bodies: tuple[tuple[int, BodyFields, BodyModel], ...] = ()
        self._smooth: SmoothTable | None = None
        self._courses: dict[tuple[float, ...], tuple[tuple, tuple, bool, bool]] = {}

    def predict(
        self,
        observation: np.ndarray,
        state: Any = None,
        episode_start: np.ndarray | None = None,
        deterministic: bool = True,
    ) -> tuple[np.ndarray, Any]:
        """Action(s) for one observation or a batch of them; the state is passed through.

        A goal-conditioned (Dict) observation is read through its ``observation`` entry, which
        holds the flat observation. On an env of another view the observation must be the one
        the env last returned: the action is that for the env's planner view of it.
        """
        obs = planner_input(self._planner, observation)
        if obs.ndim == 1:
            return self.action(obs), state
        return np.stack([self.action(o) for o in obs]), state

    def action(self, observation: np.ndarray) -> np.ndarray:
        """Normalised action for one flat observation of the planner's view (as it is: on an
        env of another view :meth:`predict` reads the env's planner view first).

        The observation is read once into Python floats (``float32`` value plus its
        ``_residual``, in double precision) and the whole step runs in plain floats.
        """
        model = self.model
        observation = np.asarray(observation)
        if observation.shape != (model.layout.size,):
            raise ValueError(
                f"observation has shape {observation.shape}, the env's layout expects "
                f"({model.layout.size},)"
            )
        if self._fields_of is not model:  # built lazily: ``model`` may be reassigned
            self._bodies = tuple(
                (i, BodyFields(model.layout, i), body) for i, body in enumerate(model.bodies)
            )
            self._fields_of = model
            self._courses.clear()  # a new model may bring another end rule
        values = observation.tolist()
        if not math.isfinite(sum(values)):  # NaN or inf anywhere makes the sum non-finite
            raise ValueError("observation contains non-finite values")
        forces, torques, rotations = [], [], []
        for index, fields, body in self._bodies:
            rotation = fields.rotation(values)
            force, torque = self._body_wrench(index, fields, body, values, rotation)
            forces.append(force)
            torques.append(torque)
            rotations.append(rotation)
        return model.action_from_wrenches(forces, torques, rotations)

    def _body_wrench(
        self, index: int, f: BodyFields, body: BodyModel, o: list[float], rotation: tuple
    ) -> tuple[tuple, tuple]:
        period = self.model.control_dt
        omega = f.vec(o, f.angular_velocity)
        # ``exact``: a goal is reached on the next tick, so the rotation must land exactly too
        # (the tracked point moves with it).
        rotation_change, exact, smooth_rotation = None, False, False
        track = f.orientation_track
        time_left = o[track.time_left] + o[track.time_left_residual]
        if o[track.flags] > 0.5 and time_left > 0.5 * period:
            phi = f.vec(o, track.deviation)
            smooth = self._smooth_course(index, "orientation", o, track)
            if smooth is not None:  # every tick lands exactly (baselines.controllers.smooth_table)
                smooth_rotation = True
                phi, time_left, rows, end_rate, rate = _toward_subgoal(
                    smooth, phi, time_left, period
                )
            if time_left <= period * (1.0 + GOAL_TICK_SLACK):
                exact, phi_next = True, _ZERO3
            else:
                if smooth is None:
                    phi_dot = left_jacobian_inverse_apply(phi, omega)
                    phi_next = self._next_deviation(o, track, phi, phi_dot, time_left, period)
                else:
                    phi_next = next_deviation(rows, phi, rate, time_left, end_rate, period)
            rotation_change = quat.mul(quat.exp(phi_next), quat.exp((-phi[0], -phi[1], -phi[2])))
        displacement = None
        track = f.position_track
        time_left = o[track.time_left] + o[track.time_left_residual]
        if o[track.flags] > 0.5 and time_left > 0.5 * period:
            deviation = f.vec(o, track.deviation)
            smooth = self._smooth_course(index, "position", o, track)
            if smooth is not None:
                deviation, time_left, rows, end_rate, rate = _toward_subgoal(
                    smooth, deviation, time_left, period
                )
            if time_left <= period * (1.0 + GOAL_TICK_SLACK):
                exact, deviation_next = True, _ZERO3
            elif smooth is None:
                deviation_next = self._next_deviation(
                    o, track, deviation, f.vec(o, f.point_velocity), time_left, period
                )
            else:
                deviation_next = next_deviation(rows, deviation, rate, time_left, end_rate, period)
            displacement = (
                deviation_next[0] - deviation[0],
                deviation_next[1] - deviation[1],
                deviation_next[2] - deviation[2],
            )
        return body_wrench(
            self.model, body, rotation, omega, f.vec(o, f.linear_velocity),
            f.vec(o, f.point_offset), displacement, rotation_change,
            exact_rotation=exact or smooth_rotation, refine=self.refine,
        )  # fmt: skip

    def _next_deviation(self, o, track: TrackFields, deviation, rate, time_left, period):
        """The re-solved rest of the current course, one control period ahead.

        On a solved matched track the observed rate is first moved ``period / (n + 1)`` along
        the course's acceleration (``n``: physics substeps per control period, see
        :func:`substep_lag`): a course re-solved every tick from the observed rate drifts off
        its plan otherwise (0.15 m over the teal rod's 1.47 s course), and the acceleration it
        reaches at the goal is then not the one the next course starts with. Not where the
        acceleration jumps at goals (the other rules, unsolved tracks): there the first tick of
        a course would be moved along the wrong acceleration (measured: a somersault rod's
        angular kink 81 -> 119 rad/s²).
        """
        key = tuple(o[track.course : track.course + COURSE_SIZE])
        course = self._courses.get(key)
        if course is None:
            rule = self.end_rule or self.model.end_rule
            matched = self._matched(key) if rule == "matched" and key[12] <= 0.5 else None
            fallback = "tangent" if rule in ("matched", "smooth") else rule
            course = _course_constants(key, fallback, matched)
            if len(self._courses) >= _CACHE_SIZE:
                self._courses.clear()
            self._courses[key] = course
        end_velocity, rows, smooth_rest, solved = course
        lag = substep_lag(period, self.model.substeps) if solved else 0.0
        return next_deviation(
            rows, deviation, rate, time_left, end_velocity, period, smooth_rest, lag
        )

    def _smooth_course(
        self, index: int, name: str, o: list[float], track: TrackFields
    ) -> SmoothCourse | None:
        """The current course's sub-goals under the smooth rule; None under another rule or
        for a course of another scenario (it then ends by the tangent rule)."""
        if (self.end_rule or self.model.end_rule) != "smooth":
            return None
        lookup = (index, name, course_key(o[track.course : track.course + 8]))
        table = self._smooth
        scenario = self._new_scenario(table is not None, table is not None and lookup in table)
        if scenario is not None:
            self._smooth = smooth_table(scenario)
        return None if self._smooth is None else self._smooth.get(lookup)

    def _new_scenario(self, loaded: bool, found: bool) -> Any | None:
        """The episode's scenario when a rule's table must be (re)built from it: none is
        loaded yet, or a course is not found and the env's scenario has changed; else None."""
        if loaded and (found or self._env is None):
            return None
        scenario = self._scenario if self._env is None else base_env(self._env).scenario
        if scenario is None or (loaded and scenario is self._scenario):
            return None
        self._scenario = scenario
        return scenario

    def _matched(self, key: tuple[float, ...]) -> tuple[tuple[float, float, float], bool] | None:
        """The matched end velocity of an interior course and whether its track was solved,
        or None for an unknown course."""
        lookup = course_key(key)
        table = self._table
        scenario = self._new_scenario(table is not None, table is not None and lookup in table)
        if scenario is not None:
            self._table = matched_table(scenario)
        return None if self._table is None else self._table.get(lookup)


def _toward_subgoal(
    course: SmoothCourse, deviation: tuple, time_left: float, period: float
) -> tuple[tuple, float, tuple, tuple, tuple]:
    """The deviation from the next sub-goal, the time to it, the frame of its sub-course, the
    reference's velocity there and the sub-course's planned rate now
    (:mod:`baselines.controllers.smooth_table`). Deviations are measured from the reference's
    sub-goal (for a rotation its principal log: the env's unwrapped deviation can take the other
    way round than the reference), but on the tick that reaches a real goal the env's deviation
    is kept, so the goal is met exactly."""
    sub = course.subgoals
    now = course.end_tick - round(time_left / period)
    j = min(bisect.bisect_right(sub.ticks, now), len(sub.ticks) - 1)
    knot = sub.ticks[j]
    time_to = time_left - (course.end_tick - knot) * period
    if not (knot == course.end_tick and course.real and time_to <= period * (1 + GOAL_TICK_SLACK)):
        value, target = sub.values[j], course.target
        if sub.orientation:
            here = quat.mul(quat.exp(deviation), target)
            deviation = quat.log(quat.mul_conjugate(here, value))
        else:
            deviation = tuple(d + t - v for d, t, v in zip(deviation, target, value, strict=True))
    rate = sub.planned_rate(j, knot - time_to / period, period)
    return deviation, time_to, sub.rows[j], sub.velocities[j], rate


def substep_lag(period: float, substeps: int) -> float:
    """How far behind the plan's rate an observed rate is, as a ``lag`` for
    :func:`~sgc_env.paper.frames.next_deviation`.

    A force held over ``n`` semi-implicit substeps of ``h = H / n`` that lands the body on
    the plan's next sample moves it by ``H v + (n + 1) / (2 n) H^2 a``, so the velocity it
    leaves with is ``D' + n / (n + 1) H D''`` where the plan has ``D' + H D''``: behind by
    ``H D'' / (n + 1)``, i.e. the mean over the last ``2 H / (n + 1)`` seconds.
    """
    return 2.0 * period / (substeps + 1)


def _course_constants(
    key: tuple[float, ...], rule: str,
    matched: tuple[tuple[float, float, float], bool] | None = None,
) -> tuple[tuple, tuple, bool, bool]:  # fmt: skip
    """World end velocity, ``S_i`` rows, whether the course arrives at rest on the quartic
    (a matched course before a dwell) and whether it is on a solved matched track, from its
    observation entries."""
    start, duration, nxt, next_duration, end_velocity = (
        key[0:3], key[3], key[4:7], key[7], key[8:11]
    )  # fmt: skip
    is_last = key[12] > 0.5
    velocity, info = course_end_velocity(
        start, None if is_last else nxt, duration, None if is_last else next_duration,
        end_velocity=end_velocity if is_last else None, rule=rule,
    )  # fmt: skip
    rows = _IDENTITY_ROWS if info.frame is None else tuple(map(tuple, info.frame.tolist()))
    if matched is None:
        return tuple(velocity.tolist()), rows, False, False
    end, solved = matched
    return end, rows, end == _ZERO3 and info.rule in ("rest", "dwell"), solved
