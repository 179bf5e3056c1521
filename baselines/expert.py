"""The analytic expert: the paper's sequential-goal controller as a stateless policy.

Every control step the expert re-plans the rest of the current course from the measured state
(the SGC family is time-consistent, so with nothing disturbing the body this *is* the plan
made at the course start) and then chooses the force and torque that land the body exactly on
the plan's next sample, through the known PyBullet integrator (:mod:`baselines.tracking`). On
the tick that reaches a goal the next sample is the goal itself, so goals are met to floating
point. A push mid-course simply becomes a new measured state to re-plan from.

The policy reads only the observation (plus the env's constants in :class:`EnvModel`), so it
runs inside ``evaluate_policy``, vector envs and imitation tools.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

from baselines.actuation import BodyObservation, read_body, wrench_for_targets
from baselines.env_model import EnvModel
from baselines.sgc.frames import FrameCourse, course_end_velocity, solve_course_in_frame
from baselines.sgc.orientation import left_jacobian_inverse

__all__ = ["SGCExpert"]

GOAL_TICK_SLACK = 1e-6
"""A goal is on the next tick when its time left is within this relative slack of one period."""


class SGCExpert:
    """Sequential-goal constraints expert with an SB3-style ``predict``.

    Build it from the environment it will drive (``SGCExpert(env)``, wrapped or vectorised
    envs too): it needs the bodies' masses, inertias and action limits, which are constants of
    the env rather than observations.
    """

    def __init__(self, env: Any | None = None, *, model: EnvModel | None = None) -> None:
        if model is None:
            if env is None:
                raise ValueError("SGCExpert needs an env or an EnvModel")
            model = EnvModel.from_env(env)
        self.model = model

    def predict(
        self,
        observation: np.ndarray,
        state: Any = None,
        episode_start: np.ndarray | None = None,
        deterministic: bool = True,
    ) -> tuple[np.ndarray, Any]:
        """Action(s) for one observation or a batch of them; the state is passed through.

        A goal-conditioned (Dict) observation is read through its ``observation`` entry, which
        holds the flat observation.
        """
        if isinstance(observation, dict):
            observation = observation["observation"]
        obs = np.asarray(observation)
        if obs.ndim == 1:
            return self.action(obs), state
        return np.stack([self.action(o) for o in obs]), state

    def action(self, observation: np.ndarray) -> np.ndarray:
        """Normalised action for one flat observation."""
        model = self.model
        if np.shape(observation) != (model.layout.size,):
            raise ValueError(
                f"observation has shape {np.shape(observation)}, the env's layout expects "
                f"({model.layout.size},)"
            )
        n = len(model.bodies)
        forces, torques = np.zeros((n, 3)), np.zeros((n, 3))
        for i, body in enumerate(model.bodies):
            state = read_body(model, observation, i)
            forces[i], torques[i] = self._body_wrench(body, state)
        return model.action_from_wrenches(forces, torques)

    def _body_wrench(self, body, state: BodyObservation) -> tuple[np.ndarray, np.ndarray]:
        period = self.model.control_dt
        # ``exact``: a goal is reached on the next tick, so the rotation must land exactly too
        # (the tracked point moves with it).
        rotation_change, exact = None, False
        if state.has_goal_ahead("orientation", period):
            track = state.orientation_track
            phi = track["deviation"]
            if _goal_on_next_tick(track, period):
                exact = True
                phi_next = np.zeros(3)
            else:
                phi_dot = left_jacobian_inverse(phi) @ state.angular_velocity
                phi_next = _course(track, phi, phi_dot).state(period)[0]
            rotation_change = Rotation.from_rotvec(phi_next) * Rotation.from_rotvec(-phi)
        displacement = None
        if state.has_goal_ahead("position", period):
            track = state.position
            deviation = track["deviation"]
            if _goal_on_next_tick(track, period):
                exact = True
                deviation_next = np.zeros(3)
            else:
                deviation_next = _course(track, deviation, state.point_velocity).state(period)[0]
            displacement = deviation_next - deviation
        return wrench_for_targets(
            self.model, body, state, point_displacement=displacement,
            rotation_change=rotation_change, exact_rotation=exact,
        )


def _goal_on_next_tick(track: dict[str, np.ndarray], period: float) -> bool:
    return float(track["time_left"][0]) <= period * (1.0 + GOAL_TICK_SLACK)


def _course(track: dict[str, np.ndarray], deviation: np.ndarray, rate: np.ndarray) -> FrameCourse:
    """The rest of the current course, re-solved from the measured deviation and its rate."""
    is_last = track["flags"][1] > 0.5
    end_velocity, info = course_end_velocity(
        track["course_start"],
        None if is_last else track["next_start"],
        float(track["course_duration"][0]),
        None if is_last else float(track["next_duration"][0]),
        end_velocity=track["end_velocity"] if is_last else None,
    )
    time_left = float(track["time_left"][0])
    return solve_course_in_frame(info.frame, deviation, rate, time_left, end_velocity)
