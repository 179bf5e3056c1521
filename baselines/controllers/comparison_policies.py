"""The two comparison baselines as SB3-style policies on the env's observation.

Both turn a next-tick target into a force and torque through :func:`wrench_for_targets`, the
same deadbeat actuation as :class:`~baselines.controllers.expert.SGCExpert`, so the three differ
*only* in how they choose targets:

- :class:`DynamicConstraintsController` (Barzel & Barr 1988): every deviation component
  decays by the critically damped law; a goal is met when |D| < eps and the controller then
  moves on, whatever the clock says (the paper's Figure 1 pathology).
- :class:`MinimumJerkController`: tracks the C4 minimum-jerk spline through the same goals at
  the same times, built from the env's resolved scenario at each episode start.

Both keep a little per-episode state (one slot per sub-env of a vector env) and reset it at
``episode_start`` or whenever the observation's time is back at tick 0. On an env that
observes another view than the planner's (the learner's view every id observes) they act, as the
expert does, on the env's planner view of its current state
(:func:`~baselines.common.planner_view.planner_reader`): ``predict`` must then be handed the
observation that env just returned.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

from baselines.common.env_model import EnvModel
from baselines.common.observation_fields import BodyObservation, read_body
from baselines.common.planner_view import planner_input, planner_reader
from baselines.common.sub_envs import base_env, sub_env
from baselines.controllers.actuation import wrench_for_targets
from baselines.controllers.dynamic_constraints import DynamicConstraintsCourse, choose_tau
from baselines.controllers.minimum_jerk import MinimumJerkPath, MinimumJerkRotation
from sgc_env.metrics import goals_from_scenario
from sgc_env.paper.orientation import left_jacobian_inverse
from sgc_env.paper.quaternion import unwrap_rotvec
from sgc_env.scenario import Scenario

__all__ = [
    "DynamicConstraintsController",
    "MeetEvent",
    "MinimumJerkController",
    "episode_model",
    "new_episode_flags",
    "observation_tick",
    "scenario_of",
    "sub_env",
]

_TRACKS = ("position", "orientation")


def episode_model(env: Any, index: int = 0) -> EnvModel:
    """The :class:`EnvModel` of sub-env ``index`` *now*.

    Read it again after every reset: a random-scenario env redraws masses and force and
    torque limits per episode, so a model read at construction goes stale.
    """
    return EnvModel.from_env(sub_env(env, index))


def scenario_of(env: Any, index: int = 0) -> Scenario:
    """The resolved scenario of sub-env ``index`` (plain, wrapped or vector env)."""
    return base_env(env, index).scenario


def observation_tick(model: EnvModel, observation: np.ndarray) -> int:
    """Control tick of an observation (its float32 time, rounded to the control grid)."""
    t = float(np.asarray(observation)[model.layout.global_slice("time")][0])
    return int(round(t / model.control_dt))


def new_episode_flags(episode_start: Any, n: int) -> np.ndarray:
    """``episode_start`` as n booleans (None: all False)."""
    if episode_start is None:
        return np.zeros(n, dtype=bool)
    return np.broadcast_to(np.asarray(episode_start, dtype=bool).reshape(-1), (n,))


def predict_per_env(
    observation: Any,
    episode_start: Any,
    row_action: Callable[[int, np.ndarray, bool], np.ndarray],
) -> np.ndarray:
    """``row_action(env_index, observation_row, episode_start)`` over one observation or a batch.

    Vector envs hand policies a batch of rows, one per sub-env; a policy with per-episode state
    keeps it per row index.
    """
    obs = np.asarray(observation)
    batch = obs.ndim == 2
    rows = obs if batch else obs[None]
    starts = new_episode_flags(episode_start, rows.shape[0])
    actions = [
        row_action(i, row, bool(start))
        for i, (row, start) in enumerate(zip(rows, starts, strict=True))
    ]
    return np.stack(actions) if batch else actions[0]


class _StatefulPolicy:
    """``predict`` over one observation or a batch, with one state slot per sub-env."""

    def __init__(self, env: Any) -> None:
        self.env = env
        self.model = EnvModel.from_env(env)
        self._planner = planner_reader(env, type(self).__name__)  # None: the planner's view
        self._slots: dict[int, Any] = {}
        self._models: dict[int, EnvModel] = {}
        self._last_tick: dict[int, int] = {}

    def predict(
        self,
        observation: np.ndarray,
        state: Any = None,
        episode_start: np.ndarray | None = None,
        deterministic: bool = True,
    ) -> tuple[np.ndarray, Any]:
        """Action(s) for one observation or a batch (a goal env's Dict read through its
        ``observation`` entry); ``state`` is passed through. On an env of another view the
        observation must be the one the env last returned."""
        observation = planner_input(self._planner, observation)
        return predict_per_env(observation, episode_start, self._row_action), state

    def _row_action(self, index: int, observation: np.ndarray, episode_start: bool) -> np.ndarray:
        layout_size = self.model.layout.size
        if np.shape(observation) != (layout_size,):
            raise ValueError(
                f"observation has shape {np.shape(observation)}, the env's layout expects "
                f"({layout_size},)"
            )
        tick = observation_tick(self.model, observation)
        fresh = index not in self._slots or tick < self._last_tick[index]
        if episode_start or tick == 0 or fresh:
            self._models[index] = episode_model(self.env, index)
            self._slots[index] = self._new_episode(index, observation)
        self._last_tick[index] = tick
        model, slot = self._models[index], self._slots[index]
        t = tick * model.control_dt
        n = len(model.bodies)
        forces, torques, rotations = np.zeros((n, 3)), np.zeros((n, 3)), np.zeros((n, 4))
        for b, body in enumerate(model.bodies):
            obs_b = read_body(model, observation, b)
            rotations[b] = obs_b.orientation
            displacement, rotation_change, exact = self._targets(slot, b, obs_b, tick, t)
            forces[b], torques[b] = wrench_for_targets(
                model, body, obs_b, point_displacement=displacement,
                rotation_change=rotation_change, exact_rotation=exact,
            )  # fmt: skip
        return model.action_from_wrenches(forces, torques, rotations)

    def _new_episode(self, index: int, observation: np.ndarray) -> Any:
        raise NotImplementedError

    def _targets(
        self, slot: Any, body: int, obs: BodyObservation, tick: int, t: float
    ) -> tuple[np.ndarray | None, Rotation | None, bool]:
        raise NotImplementedError


# ------------------------------------------------------------------ dynamic constraints


@dataclass(frozen=True)
class MeetEvent:
    """The dynamic-constraints controller declared a goal met (|D| < eps) at ``time``.

    ``offset`` is the goal relative to the env's current goal at that moment: -1 late (the
    env already moved on), 0 on time or early.
    ``speed`` is |D'| (m/s, or the rate of phi in rad/s) at that tick.
    """

    time: float
    body: int
    track: str
    offset: int
    deviation: float
    speed: float


@dataclass
class _DCTrack:
    offset: int = 0
    tau: float = 1.0
    previous_time_left: float = float("inf")
    previous_course: tuple[np.ndarray, float] = (np.zeros(3), 1.0)


@dataclass
class _DCSlot:
    tracks: dict[tuple[int, str], _DCTrack] = field(default_factory=dict)
    events: list[MeetEvent] = field(default_factory=list)


def _compose(phi: np.ndarray, start: np.ndarray) -> np.ndarray:
    """Deviation to a neighbouring orientation goal: Log(Exp(phi) Exp(start)), unwrapped.

    With R = Exp(phi) R_k and R_k = Exp(start) R_j (start = the course start between the two
    goals, as the observation gives it), R = Exp(phi') R_j.
    """
    principal = (Rotation.from_rotvec(phi) * Rotation.from_rotvec(start)).as_rotvec()
    return np.array(unwrap_rotvec(principal, phi + start))


class DynamicConstraintsController(_StatefulPolicy):
    """Barzel & Barr's dynamic constraints, the paper's Figure 1 method, on the env.

    Per track (position, orientation) of each body the controller pursues its *own* current
    goal: per component D'' + (2/tau) D' + D/tau^2 = 0, each tick landing on the closed-form
    D(dt) from the measured (D, D') via deadbeat actuation. When ``|D| < eps`` (m) or
    ``eps_orientation`` (rad) the goal counts as met and the next goal starts at once.

    Goal switching versus the env's clock (the env advances goals at their times):

    - early: met before the goal's tick, the controller already pursues the next goal (the
      deviation to it is D + ``next_start``). The observation shows one goal ahead only, so
      meeting that one too before the env catches up just keeps converging on it.
    - late: when the env moves on first, the controller keeps converging on the old goal
      (deviation D - ``course_start``). If the env moves on again while it is still late, the
      old goal is no longer observable and is dropped: the controller continues with the
      goal after it (counted as missed by the metrics).
    - after the last goal it keeps converging on it.

    tau per course (:func:`choose_tau`): from rest at the nominal course start ``|D_i(0)|``
    (previous nail minus nail, from the scenario), ``|D|`` falls to eps exactly at the nominal
    course duration T_i. Courses with ``|D_i(0)| <= 2 eps`` use 2 eps. The force and torque
    limits of the env clip the law where it asks for more (it starts hard: D0/tau^2).
    Different body points per goal are not modelled: the look-ahead uses the current goal's.
    ``events`` lists the meetings of the episode in progress (last sub-env used).
    """

    def __init__(self, env: Any, eps: float = 1e-3, eps_orientation: float = 1e-3) -> None:
        for name, value in (("eps", eps), ("eps_orientation", eps_orientation)):
            if not (np.isfinite(value) and value > 0.0):
                raise ValueError(f"{name} must be finite and positive, got {value}")
        super().__init__(env)
        self.eps = float(eps)
        self.eps_orientation = float(eps_orientation)

    def meet_events(self, index: int = 0) -> list[MeetEvent]:
        """Meetings of sub-env ``index``'s current episode, in time order."""
        slot = self._slots.get(index)
        return [] if slot is None else list(slot.events)

    def _new_episode(self, index: int, observation: np.ndarray) -> _DCSlot:
        return _DCSlot()

    def _tau(self, start: np.ndarray, duration: float, eps: float) -> float:
        distance = max(float(np.linalg.norm(start)), 2.0 * eps)
        return choose_tau(max(duration, 1e-9), distance, eps)

    def _deviation(self, name: str, track: dict[str, np.ndarray], offset: int) -> np.ndarray:
        d = track["deviation"]
        if offset == 0:
            return d
        start = track["next_start"] if offset > 0 else -track["course_start"]
        if name == "position":
            return d + start
        return _compose(d, start)

    def _targets(
        self, slot: _DCSlot, body: int, obs: BodyObservation, tick: int, t: float
    ) -> tuple[np.ndarray | None, Rotation | None, bool]:
        displacement, rotation_change = None, None
        if obs.position["flags"][0] > 0.5:
            d, d_next = self._track_step(slot, body, "position", obs, t)
            displacement = d_next - d
        if obs.orientation_track["flags"][0] > 0.5:
            phi, phi_next = self._track_step(slot, body, "orientation", obs, t)
            rotation_change = Rotation.from_rotvec(phi_next) * Rotation.from_rotvec(-phi)
        return displacement, rotation_change, False

    def _track_step(
        self, slot: _DCSlot, body: int, name: str, obs: BodyObservation, t: float
    ) -> tuple[np.ndarray, np.ndarray]:
        """The deviation to the controller's goal on one track now and at the next tick."""
        dt = self.model.control_dt
        track = obs.track(name)
        eps = self.eps if name == "position" else self.eps_orientation
        course = (track["course_start"].copy(), float(track["course_duration"][0]))
        st = slot.tracks.get((body, name))
        if st is None:
            st = slot.tracks[(body, name)] = _DCTrack(tau=self._tau(*course, eps))
        time_left = float(track["time_left"][0])
        if time_left > st.previous_time_left + 0.5 * dt:
            st.offset -= 1
            if st.offset < -1:
                st.offset = -1
                st.tau = self._tau(*st.previous_course, eps)
        st.previous_time_left, st.previous_course = time_left, course
        is_last = track["flags"][1] > 0.5
        d = self._deviation(name, track, st.offset)
        while np.linalg.norm(d) < eps and (st.offset < 0 or (st.offset == 0 and not is_last)):
            speed = float(np.linalg.norm(self._rate(name, d, obs)))
            event = MeetEvent(t, body, name, st.offset, float(np.linalg.norm(d)), speed)
            slot.events.append(event)
            st.offset += 1
            if st.offset == 0:
                st.tau = self._tau(*course, eps)
            else:
                st.tau = self._tau(track["next_start"], float(track["next_duration"][0]), eps)
            d = self._deviation(name, track, st.offset)
        d_next = DynamicConstraintsCourse(d, self._rate(name, d, obs), st.tau).position(dt)
        return d, d_next

    @staticmethod
    def _rate(name: str, d: np.ndarray, obs: BodyObservation) -> np.ndarray:
        """D' for a point (its velocity), phi' = J_l(phi)^-1 omega for an orientation."""
        if name == "position":
            return obs.point_velocity
        return left_jacobian_inverse(d) @ obs.angular_velocity


# ------------------------------------------------------------------ minimum jerk


@dataclass
class _MJBody:
    path: MinimumJerkPath | None
    nails: np.ndarray
    position_ticks: np.ndarray
    rotation: MinimumJerkRotation | None
    targets: list[Rotation]
    orientation_ticks: np.ndarray


def _minimum_jerk_body(scenario: Scenario, body_index: int, control_frequency: int) -> _MJBody:
    body = scenario.bodies[body_index]
    goals = goals_from_scenario(scenario)[body_index]
    q0 = Rotation.from_quat(np.asarray(body.orientation, dtype=float))
    omega0 = np.asarray(body.angular_velocity, dtype=float)
    pos_goals = [g for g in goals if g.nail is not None]
    path, nails, pticks = None, np.zeros((0, 3)), np.zeros(0, dtype=int)
    if pos_goals:
        offset = q0.apply(np.asarray(pos_goals[0].point, dtype=float))
        start = np.asarray(body.position, dtype=float) + offset
        v0 = np.asarray(body.linear_velocity, dtype=float) + np.cross(omega0, offset)
        nails = np.array([g.nail for g in pos_goals], dtype=float)
        times = [0.0, *[g.time for g in pos_goals]]
        path = MinimumJerkPath(times, np.vstack([start, nails]), v0, end_velocity=body.end_velocity)
        pticks = np.rint(np.array(times[1:]) * control_frequency).astype(int)
    rot_goals = [(j, g) for j, g in enumerate(goals) if g.orientation is not None]
    rotation, targets, oticks = None, [], np.zeros(0, dtype=int)
    if rot_goals:
        quats = [np.asarray(body.orientation, dtype=float)]
        rotations = []
        previous = q0
        for j, g in rot_goals:
            target = Rotation.from_quat(np.asarray(g.orientation, dtype=float))
            rel = body.goals[j].relative_rotation
            rotations.append(
                np.asarray(rel, dtype=float)
                if rel is not None
                else (target * previous.inv()).as_rotvec()
            )
            quats.append(np.asarray(g.orientation, dtype=float))
            targets.append(target)
            previous = target
        times = [0.0, *[g.time for _, g in rot_goals]]
        rotation = MinimumJerkRotation(
            times, np.array(quats), omega0, rotations=rotations, end_omega=body.end_angular_velocity
        )
        oticks = np.rint(np.array(times[1:]) * control_frequency).astype(int)
    return _MJBody(path, nails, pticks, rotation, targets, oticks)


class MinimumJerkController(_StatefulPolicy):
    """Deadbeat tracking of the minimum-jerk spline through the goals at their times.

    At each episode start (``episode_start``, or an observation at tick 0) the controller
    reads the sub-env's resolved scenario and builds, per body, a :class:`MinimumJerkPath`
    for the tracked point through the nails and a :class:`MinimumJerkRotation` through the
    orientation goals (somersaults via their relative rotation vectors), from the initial
    state with the scenario's end velocities. Each tick it lands the body on the spline at the
    next tick (on a goal tick: on the goal itself), so goals are met to the deadbeat's
    precision and the velocity is continuous. After a track's last goal it applies no
    control on that track (gravity compensated), like the expert. The spline follows the
    first goal's body point: it assumes one tracked point per body.
    """

    def _new_episode(self, index: int, observation: np.ndarray) -> list[_MJBody]:
        scenario = scenario_of(self.env, index)
        if len(scenario.bodies) != len(self.model.bodies):
            raise ValueError(
                f"scenario has {len(scenario.bodies)} bodies, the policy was built for "
                f"{len(self.model.bodies)}"
            )
        freq = int(round(1.0 / self.model.control_dt))
        return [_minimum_jerk_body(scenario, b, freq) for b in range(len(scenario.bodies))]

    def _targets(
        self, slot: list[_MJBody], body: int, obs: BodyObservation, tick: int, t: float
    ) -> tuple[np.ndarray | None, Rotation | None, bool]:
        plan = slot[body]
        t_next = t + self.model.control_dt
        displacement = None
        if plan.path is not None and tick < plan.position_ticks[-1]:
            k = int(np.searchsorted(plan.position_ticks, tick, side="right"))
            here = plan.nails[k] + obs.position["deviation"]
            if plan.position_ticks[k] == tick + 1:
                target = plan.nails[k]
            else:
                target = plan.path.position(t_next)
            displacement = target - here
        rotation_change, exact = None, False
        if plan.rotation is not None and tick < plan.orientation_ticks[-1]:
            k = int(np.searchsorted(plan.orientation_ticks, tick, side="right"))
            exact = bool(plan.orientation_ticks[k] == tick + 1)
            if exact:
                target_r = plan.targets[k]
            else:
                target_r = Rotation.from_quat(plan.rotation.orientation(t_next))
            rotation_change = target_r * Rotation.from_quat(obs.orientation).inv()
        return displacement, rotation_change, exact
