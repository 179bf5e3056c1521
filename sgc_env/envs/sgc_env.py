"""The sequential-goal environment: rigid bodies driven by forces and torques on PyBullet.

## Description

Each body of a :class:`~sgc_env.scenario.Scenario` must meet a sequence of goals: a body point
on a world nail and/or a body orientation, each at a goal time (Liu, Ko & Chang 1993). Goals
are met *exactly* and *punctually* only by planning; nothing in the env snaps bodies to goals.

## Action space

``Box(-1, 1, (6 * n_bodies,))``: per body force xyz then torque xyz, both in the world frame.
The force is scaled by the body's ``force_limit`` (N). The torque is scaled per principal axis,
``tau = R0 diag(torque_scale) R0^T a`` with ``torque_scale = torque_limit * I / max(I)`` (N m;
``env.torque_scale``, one row per body) and ``R0`` the body's orientation at the start of the
control step: a torque action is an angular-acceleration command, and an action of 1 along
any direction gives the same angular acceleration ``torque_limit / max(I)`` (gyroscopic terms
aside). Why: a thin rod's axial inertia is ~70 times smaller than its transverse one, so with a
plain world-frame torque box an action error of 1e-3 spun a 0.6 m rod at 6.7 rad/s^2 about its
axis and no learned policy met a rod orientation goal. Why world axes rather than body axes:
body-axis actions make the policy rotate its world-frame observation (phi, omega) into the
body frame, and a clone trained on them spun the rod up (1/150 goals, docs/agents.md). When
every body is a sphere without orientation goals the torque is dropped: ``(3 * n_bodies,)``.
The force acts at the centre of mass; gravity is *not* compensated. The action is held for one
control period (``sim_frequency / control_frequency`` PyBullet steps, 240 / 60 = 4 by default)
and re-applied on every substep (the torque too: it is fixed at the step's start).

## Observation space

The learner's view by default (``observation="learner"``, :mod:`sgc_env.envs.learner_view`:
per body and track the deviations and course terms scaled to their course, bounds +-3).
``observation="planner"`` observes the planner's state instead, the privileged view the
evaluation harness gives the analytic controllers (``planner_observation()`` returns it under
any view): a flat float32 ``Box`` (bounds +-1e5); per-body blocks then ``time``; offsets from
``env.unwrapped.layout`` (:class:`~sgc_env.observation.ObservationLayout`):

| field | size | meaning |
|---|---|---|
| position, orientation | 3, 4 | CoM (world), quaternion xyzw |
| linear_velocity, angular_velocity | 3, 3 | world frame |
| point_offset | 3 | the current position goal's body point (body frame) |
| position_deviation | 3 | D = world point - current nail |
| point_velocity | 3 | D' |
| position_time_left | 1 | time to the current goal; after the last one, minus the time since it |
| position_course_start, position_course_duration | 3, 1 | D_i(0) = previous nail - nail; T_i |
| position_next_start, position_next_duration | 3, 1 | nail_i - nail_{i+1}; T_{i+1} (0 if last) |
| position_end_velocity | 3 | last goal only: end velocity (default: last course average) |
| position_flags | 2 | (has a position track, current goal is the last) |
| orientation_* | 3,1,3,1,3,1,3,2 | the same for phi, R = Exp(phi) R_goal, unwrapped |
| time | 1 | seconds since reset |

The current goal advances on the tick of its time: the observation returned by the step that
reaches t_i already describes goal i+1.

## Rewards

``reward=`` (constructor, ``gym.make(id, reward=...)``) is ``"tracking"``, the one built-in
mode, or a :class:`~sgc_env.envs.rewards.RewardMode` of the caller's own
(:mod:`sgc_env.envs.rewards` has the formula and why): ``r = mean_b sum_tracks 1 / (1 + |D -
D_sched| / L) + 0.01 (1 - mean(a^2)) + bonus`` with ``D_sched = D_i(0) time_left / T_i`` (after
the last goal ``-v_end time_left``), ``D`` the tracked point's deviation, ``D_i(0)`` and ``T_i``
the current course's start deviation and duration, ``L = max(|D_i(0)|, 0.1 m)`` (the same for
orientation with ``phi`` and ``max(|phi_i(0)|, 0.5 rad)``), and ``bonus`` per goal met this tick
``exp(-|D| / 0.01 m)`` (+ ``exp(-|phi| / 0.02 rad)``); means over bodies. An unknown mode is a
``ValueError`` naming the choices.

## Episode end

``truncated`` at the last goal time + ``scenario.margin`` (reaching a goal never ends an
episode). ``terminated`` on failure: non-finite state, a body CoM outside the workspace box, or
a speed over 90 m/s (PyBullet clamps at 100 m/s). PyBullet also clamps |omega| at 100 rad/s;
that is not terminal: ``info["spin_clamped"]`` flags it (the physics is then no longer exact).

## Info

Per the contract of docs/design.md (:mod:`sgc_env.envs.step_info` builds it): per-body goal
indices, deviations, times to goal, body and point states, force and torque, ``spin_clamped``,
and on goal ticks ``goal_reached``: ``{body, goal, time, position_error, orientation_error}``
(|D| and the body-goal angle in [0, pi] at that tick; None for a missing part).

## Arguments

``scenario`` (Scenario, built-in name or YAML path) or ``random_scenario`` (a preset name of
``sgc_env.scenes.PRESETS`` or a config of a scene family, redrawn from ``np_random``
on every reset); ``control_frequency`` (default: the scenario's, 60 Hz), ``sim_frequency``
(240 Hz, an integer multiple of the control frequency), ``time_grid`` ("reject" or "snap"),
``render_mode`` ("human" uses a GUI client, "rgb_array" the look of :mod:`sgc_env.render`),
``camera`` ("fixed": frames the whole scene, "tracking": follows the bodies, or a dict, see
:class:`~sgc_env.render.scene.CameraSpec`), ``width``/``height`` (frame size, 640x480),
``reward`` (``"tracking"`` or a :class:`~sgc_env.envs.rewards.RewardMode`), ``observation``
(``"learner"``, ``"planner"`` or an :class:`~sgc_env.envs.views.ObservationView`).
``reset(options={"scenario": ...})`` swaps the scenario (same number of bodies and action size;
a random-scenario env draws again on the next plain reset).
"""

from __future__ import annotations

import struct
from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path
from typing import Any, cast

import gymnasium as gym
import numpy as np

from sgc_env.episode_steps import check_registered_length
from sgc_env.observation import BODY_BLOCK_SIZE, ObservationLayout
from sgc_env.render.camera import View
from sgc_env.render.modes import available_render_modes
from sgc_env.render.scene import CameraSpec, SceneRenderer, check_size
from sgc_env.scenario import Scenario, resolve_scenario
from sgc_env.scenario.caps import cap
from sgc_env.scenes import PRESETS, SceneFamily
from sgc_env.scenes import random_scenario as draw_random_scenario
from sgc_env.simulator import Drive, Simulator

from .actuation import Actuation, clip_action
from .failure import MAX_SPEED, SPIN_CLAMP, body_flags
from .prepare import Prepared, as_scenario, prepare_scenario, scene_geometry
from .record import body_block
from .rewards import RewardMode, StepScore, goal_bonus, make_reward, square_sum, tracks_of
from .snapshots import SavedState
from .step_info import StepInfo, step_info
from .task import GoalEvent, TaskCounters
from .vector.world import SharedWorld
from .views import OBS_BOUND, ObservationView, PlannerView, make_view

__all__ = ["MAX_SPEED", "OBS_BOUND", "SPIN_CLAMP", "SGCEnv", "SavedState", "StepInfo"]


class SGCEnv(gym.Env):
    """Sequential-goal constraints on free rigid bodies (see the module docstring)."""

    metadata = {"render_modes": ["human", "rgb_array"], "render_fps": 60}

    def __init__(
        self,
        scenario: Scenario | str | Path | None = None,
        *,
        random_scenario: SceneFamily | str | None = None,
        control_frequency: int | None = None,
        sim_frequency: int = 240,
        time_grid: str | None = None,
        render_mode: str | None = None,
        camera: str | dict[str, Any] | None = None,
        width: int = 640,
        height: int = 480,
        reward: str | RewardMode = "tracking",
        observation: str | ObservationView = "learner",
        world: SharedWorld | None = None,
    ) -> None:
        self._init_kwargs: dict[str, Any] = {
            "scenario": scenario, "random_scenario": random_scenario,
            "control_frequency": control_frequency, "sim_frequency": sim_frequency,
            "time_grid": time_grid, "render_mode": render_mode, "camera": camera,
            "width": width, "height": height, "reward": reward, "observation": observation,
        }  # fmt: skip
        self.reward_mode = reward
        self._reward = make_reward(reward)
        self._score = StepScore([], 1, 0.0, 1, 0.0, False, 0)  # filled every step
        self._view = make_view(observation)
        if render_mode is not None and render_mode not in type(self).metadata["render_modes"]:
            raise ValueError(f"render_mode must be 'human' or 'rgb_array', got {render_mode!r}")
        if scenario is None and random_scenario is None:
            raise ValueError(
                "give a scenario (object, built-in name or YAML path) or random_scenario"
            )
        self.render_mode = render_mode
        self.camera = CameraSpec.parse(camera)
        self.width, self.height = check_size("width", width), check_size("height", height)
        self._random_config: SceneFamily | None = None
        if scenario is None:
            cfg = (
                PRESETS[random_scenario]
                if isinstance(random_scenario, str)
                else cast(SceneFamily, random_scenario)  # not None: checked above
            )
            if control_frequency is not None:
                cfg = replace(cfg, control_frequency=control_frequency)
            self._random_config = cfg
            base = draw_random_scenario(np.random.default_rng(0), cfg)
        else:
            base = as_scenario(scenario)
        self._control_override = control_frequency
        self._time_grid = time_grid
        base = self._resolve(base)
        self.sim_frequency = int(sim_frequency)
        cf = base.control_frequency
        if self.sim_frequency <= 0 or self.sim_frequency % cf:
            raise ValueError(
                f"sim_frequency {sim_frequency} Hz must be a positive integer multiple of the "
                f"control frequency {cf} Hz"
            )
        if self.sim_frequency > cap("sim_frequency"):
            raise ValueError(
                f"sim_frequency {sim_frequency} Hz is over the cap of {cap('sim_frequency')} Hz "
                "(every control tick runs sim_frequency / control_frequency PyBullet steps)"
            )
        self.control_frequency = cf
        self.substeps = self.sim_frequency // cf
        self.dt = 1.0 / cf
        # "human" is offered only where a display exists, so headless checkers do not open a GUI.
        self.metadata = {
            **type(self).metadata,
            "render_fps": cf,
            "render_modes": available_render_modes(),
        }
        self._n = len(base.bodies)
        self._score.n_bodies = self._n
        self.use_torque = not all(
            b.shape == "sphere" and not b.has_orientation_track for b in base.bodies
        )
        per = 6 if self.use_torque else 3
        self.action_space = gym.spaces.Box(-1.0, 1.0, (per * self._n,), np.float32)
        self._action_shape = self.action_space.shape
        self.layout = ObservationLayout(self._n, tuple(b.name for b in base.bodies))
        self._block_end = self.layout.size
        # The step record (planner blocks, residual slots holding residuals, the time, then
        # point positions, forces and torques: sgc_env.envs.record), packed once per step.
        self._record = struct.Struct(f"{self.layout.size + 9 * self._n}d")
        self._view = self._view.bind(self.layout)
        self._planner_view = PlannerView().bind(self.layout)
        self.observation_space = self._view.space()
        self._renderer: SceneRenderer | None = None
        self._closed = False
        self.scenario: Scenario = base
        self._geometry: tuple = ()
        # Everything that can reject the scenario runs before the PyBullet client exists; if
        # building the scene still fails, the client is closed before the error propagates.
        self._world = world
        if world is not None:
            if render_mode is not None:
                raise ValueError("render_mode: a sub-env of a batched env does not render")
            world.check_frequency(self.sim_frequency)
        prepared = self._prepare(base)
        self.sim = (
            Simulator(gui=render_mode == "human", sim_frequency=self.sim_frequency)
            if world is None
            else world.view()
        )
        try:
            self._build(base)
            self._commit(prepared)
            self._reset_state()
        except BaseException:
            self.sim.close()
            raise

    # ---------------------------------------------------------------- scenario handling

    def _resolve(self, s: Scenario) -> Scenario:
        if (
            s.resolved
            and self._control_override in (None, s.control_frequency)
            and self._time_grid is None
        ):
            return s
        return resolve_scenario(
            s, control_frequency=self._control_override, time_grid=self._time_grid
        )

    def _build(self, s: Scenario) -> None:
        """Create bodies and props (once per geometry; resets only move them)."""
        for name in list(self.sim.bodies):
            self.sim.remove_body(name)
        for b in s.bodies:
            self.sim.add_body(b.name, b.shape, b.size, b.mass, b.color, collisions=b.collisions)
        for p in s.props:
            self.sim.add_body(
                p.name, p.shape, p.size, 0.0, p.color, kinematic=True, collisions=p.collisions
            )
        self._uids = [self.sim.bodies[b.name].uid for b in s.bodies]
        self._prop_uids = [self.sim.bodies[p.name].uid for p in s.props]
        self.body_inertia = np.array([self.sim.inertia_diagonal(b.name) for b in s.bodies])
        self._geometry = scene_geometry(s)

    def _set_scenario(self, s: Scenario) -> None:
        """Switch to ``s`` all at once: everything is checked and compiled before the env
        changes, so a rejected scenario leaves the env exactly as it was."""
        self._commit(self._prepare(s))

    def _prepare(self, s: Scenario) -> Prepared:
        """Check ``s`` against this env and compile its tracks; changes nothing."""
        return prepare_scenario(
            s, n_bodies=self._n, use_torque=self.use_torque,
            control_frequency=self.control_frequency, sim_frequency=self.sim_frequency,
            world=self._world,
        )  # fmt: skip

    def _commit(self, prepared: Prepared) -> None:
        """Make a prepared scenario current. Rebuilding bodies is the one step that talks to
        PyBullet; if it fails, the previous scene is rebuilt before the error propagates."""
        s = prepared.scenario
        if scene_geometry(s) != self._geometry:
            previous = self.scenario
            try:
                self._build(s)
            except BaseException:
                self._build(previous)
                raise
        self.scenario = s
        self.sim.set_gravity(s.gravity)
        self.task = prepared.task
        self.max_steps = prepared.max_steps
        self._props = prepared.props
        self._actuation = Actuation(
            s, self.body_inertia, self._uids, use_torque=self.use_torque,
            substeps=self.substeps, sim_frequency=self.sim_frequency,
        )  # fmt: skip
        self.torque_scale = self._actuation.torque_scale
        self._view_constants = self._view.constants(self)
        self._ws_low, self._ws_high = (tuple(map(float, corner)) for corner in s.workspace[:2])

    @property
    def observation_view(self) -> str:
        """The name of the view observed: ``"planner"``, ``"learner"`` or a custom view's."""
        return self._view.name

    def planner_observation(self) -> np.ndarray:
        """The planner's view of the current state under any ``observation`` (the expert's)."""
        return self._planner_view.observe(np.append(self._block, self._tick * self.dt))

    @property
    def last_observation(self) -> np.ndarray:
        """The flat observation last handed out, in this env's view (planner policies check it)."""
        return self._obs

    # ---------------------------------------------------------------- reset / step

    def reset(  # type: ignore[override]  # StepInfo is a TypedDict, at runtime the dict promised
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, StepInfo]:
        self._check_open()
        options = options or {}
        prepared = None
        if options.get("scenario") is not None:
            # Checked and compiled before the seed or anything else changes (transactional).
            prepared = self._prepare(self._resolve(as_scenario(options["scenario"])))
        super().reset(seed=seed)
        if prepared is not None:
            self._commit(prepared)
        elif self._random_config is not None:
            self._set_scenario(draw_random_scenario(self.np_random, self._random_config))
        self._reset_state()
        if self._world is None:  # the batched env checks against its own limit
            check_registered_length(self.spec, self.max_steps)
        info = self._info([])
        if self.render_mode == "human":
            self.render()
        return self._obs, info

    def _reset_state(self) -> None:
        for uid, b in zip(self._uids, self.scenario.bodies, strict=True):
            self.sim.reset_body(
                uid, b.position, b.orientation, b.linear_velocity, b.angular_velocity
            )
        if self._prop_uids:
            for uid, pos in zip(self._prop_uids, self._props.at(0), strict=True):
                self.sim.move(uid, pos)
        self._tick = 0
        self._applied = self._actuation.idle
        self.task.reset()
        self._observe()

    def _observe(self, read: bool = True) -> None:
        """Read every body once, let the task measure it, and build the step record, the
        observation and the failure and spin-clamp flags (the rules of :mod:`.record`,
        :mod:`.failure` and the view, which the batched env runs on arrays).

        Pure-Python arithmetic on tuples, one struct pack into a fresh buffer and one cast:
        for a few bodies that is several times cheaper than numpy calls on 3-vectors.
        ``read=False`` rebuilds from the last read (after a goal switch) without calling
        PyBullet again.
        """
        if read:
            self._states = self.sim.body_states(self._uids)
        t = self._tick * self.dt
        task = self.task
        task.measure(self._states, t)
        offsets, residuals = task.offsets, task.offset_residuals
        devs, phis = task.deviations, task.phi
        ptls, otls = task.position_time_left, task.orientation_time_left
        pcourse, ocourse = task.position_course, task.orientation_course
        flat: list[float] = []
        ok = True
        spin = False
        lo, hi = self._ws_low, self._ws_high
        for i, state in enumerate(self._states):
            flat += body_block(
                state, offsets[i], devs[i], ptls[i], pcourse[i], phis[i], otls[i], ocourse[i],
                residuals[i],
            )  # fmt: skip
            fine, clamped = body_flags(state, lo, hi)
            ok = ok and fine
            spin = spin or clamped
        flat.append(t)
        for p in task.points:
            flat += p
        flat += self._applied
        # A fresh buffer every step (callers keep old observations and infos); the info
        # entries are views of it instead of separate allocations.
        buffer = bytearray(self._record.size)
        self._record.pack_into(buffer, 0, *flat)
        arr = np.frombuffer(buffer)
        size = self._block_end
        self._obs = self._view.observe(arr, self._view_constants)
        self._block = arr[: size - 1].reshape(self._n, BODY_BLOCK_SIZE)
        self._tail = arr[size:].reshape(3, self._n, 3)
        self._failed = not ok
        self._spin_clamped = spin

    def step(  # type: ignore[override]  # StepInfo is a TypedDict, at runtime the dict promised
        self, action: np.ndarray
    ) -> tuple[np.ndarray, float, bool, bool, StepInfo]:
        if self._closed:
            self._check_open()
        values = clip_action(action, self._action_shape)
        drives, moves = self._drives(values)
        self.sim.step_bodies(drives, moves)
        return self._finish_step(values)

    def _drives(
        self, values: list[float]
    ) -> tuple[list[Drive], list[list[tuple[int, list[float]]]]]:
        """The bodies' drives and the props' moves (one list per substep) of the next control
        period; the batched env gathers these from every sub-env into one physics step."""
        drives, self._applied = self._actuation.drives(values, self._states)
        moves: list[list[tuple[int, list[float]]]] = []
        if self._prop_uids:
            base = self._tick * self.substeps
            at = self._props.at
            moves = [
                list(zip(self._prop_uids, at(base + k + 1), strict=True))
                for k in range(self.substeps)
            ]
        return drives, moves

    def _finish_step(self, values: list[float]) -> tuple[Any, float, bool, bool, StepInfo]:
        """Everything after the physics of a control step: observe, goal events, reward."""
        self._tick += 1
        self._observe()
        task = self.task
        events: list[GoalEvent] = []
        if self._tick >= task.next_event >= 0:
            events, changed = task.advance(self._tick)
            if changed:
                self._observe(read=False)
        terminated = self._failed
        score = self._score  # one per env, refilled: the mode reads it during this call only
        score.tracks, score.square_sum = tracks_of(task), square_sum(values)
        score.action_size, score.bonus = len(values), goal_bonus(events)
        score.failed, score.steps_left = terminated, self.max_steps - self._tick
        reward = self._reward.reward(score)
        truncated = (not terminated) and self._tick >= self.max_steps
        info = self._info(events)
        if self.render_mode == "human":
            self.render()
        return self._obs, reward, terminated, truncated, info

    def _info(self, events: list[GoalEvent]) -> StepInfo:
        return step_info(
            self._block, self._tail, self.task, self._tick * self.dt, self._spin_clamped, events
        )

    def _counters(self) -> dict[str, Any]:
        return {"tick": self._tick, "task": self.task.counters(), "scenario": self.scenario}

    def _apply_counters(self, c: dict[str, Any]) -> None:
        if c["scenario"] is not self.scenario:
            self._set_scenario(c["scenario"])
        self._tick = c["tick"]
        task_counters: TaskCounters = c["task"]
        self.task.restore(task_counters, self._tick)

    def save_state(self) -> SavedState:
        """Snapshot physics (PyBullet saveState, in memory, ~100 KB) and the goal counters.

        The PyBullet copy is freed by :meth:`SavedState.free` (or :meth:`free_state`), when the
        snapshot is garbage-collected, or when the env closes, whichever comes first.
        """
        self._check_open()
        return SavedState.of(self.sim, self._counters())

    def free_state(self, state: SavedState) -> None:
        """Free a snapshot's PyBullet copy now (restoring it afterwards is an error)."""
        state.free()

    def restore_state(self, state: SavedState) -> np.ndarray:
        """Return to a :meth:`save_state` snapshot; returns the observation there."""
        self._check_open()
        if not state.alive:
            raise ValueError("this saved state was freed (SavedState.free); save a new one")
        self.sim.restore_state(state.bullet_state)
        self._apply_counters(state.counters)
        self._observe()
        return self._obs

    def apply_impulse(
        self,
        body: int | str,
        linear: Sequence[float],
        angular: Sequence[float] = (0.0, 0.0, 0.0),
    ) -> np.ndarray:
        """Push a body between steps (a disturbance); returns the observation after the push.

        ``linear`` (N s) and ``angular`` (N m s, world frame, about the centre of mass) change
        the body's velocities at once, as an impact would. Policies see the push in the
        returned observation, which replaces the one from the last step.
        """
        self._check_open()
        i = self.scenario.body_index(body) if isinstance(body, str) else int(body)
        if not 0 <= i < self._n:
            raise ValueError(f"body: no body {body!r} in a scene of {self._n}")
        dp, dl = np.asarray(linear, dtype=float), np.asarray(angular, dtype=float)
        if dp.shape != (3,) or dl.shape != (3,) or not np.all(np.isfinite([*dp, *dl])):
            raise ValueError(f"impulse must be two finite 3-vectors, got {linear!r}, {angular!r}")
        pos, orn, _, _ = self._states[i]
        self.sim.reset_body(
            self._uids[i], pos, orn, *self._actuation.impulse(i, self._states[i], dp, dl)
        )
        self._observe()
        return self._obs

    def __getstate__(self) -> dict[str, Any]:
        self._check_open()
        return {
            "init_kwargs": self._init_kwargs,
            "counters": self._counters(),
            "bullet": self.sim.state_bytes(),
            "rng": None if self._np_random is None else self._np_random.bit_generator.state,
        }

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.__init__(**state["init_kwargs"])  # type: ignore[misc]
        self._apply_counters(state["counters"])
        self.sim.load_state_bytes(state["bullet"])
        if state["rng"] is not None:
            rng = np.random.default_rng()
            rng.bit_generator.state = state["rng"]
            self._np_random = rng
        self._observe()

    # ---------------------------------------------------------------- rendering

    def render(self) -> np.ndarray | None:
        """``rgb_array``: a (height, width, 3) uint8 frame with the look of ``sgc demo``
        (:mod:`sgc_env.render`); ``human``: points the GUI window's camera the same way."""
        self._check_open()
        if self.render_mode is None:
            gym.logger.warn("render() called without a render_mode; pass render_mode= to the env")
            return None
        view = self.camera_view()
        if self.render_mode == "human":
            if view.orbit is not None:
                self.sim.point_gui_camera(*view.orbit)
            return None
        assert self._renderer is not None  # made by camera_view
        props = self._props.at(self._tick * self.substeps) if self._prop_uids else []
        return self._renderer.frame(
            view, self._tick * self.dt, [state[0] for state in self._states],
            [state[1] for state in self._states], self.task.points, props,
        )  # fmt: skip

    def camera_view(self) -> View:
        """The camera of the next ``render()``: ``view.project(points)`` gives pixels."""
        self._check_open()
        if self._renderer is None:
            self._renderer = SceneRenderer(self.width, self.height, self.camera)
        positions = [state[0] for state in self._states]
        return self._renderer.view(self.scenario, self.max_steps * self.dt, positions)

    def close(self) -> None:
        """Disconnect the PyBullet client (saved states go with it). Idempotent."""
        renderer = getattr(self, "_renderer", None)
        if renderer is not None:
            renderer.close()
        sim = getattr(self, "sim", None)
        if sim is not None:
            sim.close()
            self.sim = None  # type: ignore[assignment]
        self._closed = True
        super().close()

    def _check_open(self) -> None:
        if self._closed:
            raise RuntimeError("this SGCEnv is closed (close() was called); make a new env")
