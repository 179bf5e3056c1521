"""The per-step task of every sub-env of a batch at once: the single env's rules on arrays.

Why: with N sub-envs in one world the physics is a small part of a step; the rest would be N
times the single env's per-body Python. :class:`BatchTask` holds every sub-env's state in
(N, bodies, ...) arrays and calls the very rules the single env calls, with arrays over
(sub-envs, bodies) where the single env passes one body's floats: actuation
(:func:`~sgc_env.envs.actuation.body_drive`),
measurement (:func:`~sgc_env.envs.measure.measure`), failure
(:func:`~sgc_env.envs.failure.body_flags`), the reward mode (its one ``reward`` method), the
step record (:func:`~sgc_env.envs.record.body_block`) and the observation view. Goal switching
is rare and stays each sub-env's own :meth:`~sgc_env.envs.task.GoalTask.advance`, its new goal
copied into the arrays afterwards; so do resets, pushes and the props' paths.

The sub-env objects are not updated on every step: :meth:`sync` writes a sub-env's state back
into its ``SGCEnv`` (the batch does so before handing the sub-envs out) and :meth:`load`
reads it from there (after a reset, or once the sub-envs were handed out and may have been
pushed). The record (N, record) and observation (N, obs) buffers are fresh every step, so
observations and infos handed out earlier keep their values; a :meth:`load` into buffers
already handed out copies them first.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from sgc_env.observation import BODY_BLOCK_SIZE
from sgc_env.simulator import BodyReading, pybullet

from ..actuation import body_drive
from ..failure import body_flags
from ..measure import measure
from ..record import body_block, pack_blocks
from ..rewards import (
    ORIENTATION_FLOOR,
    POSITION_FLOOR,
    StepScore,
    TrackReading,
    goal_bonus,
    square_sum,
)  # fmt: skip
from ..sgc_env import SGCEnv
from ..task import GoalEvent

__all__ = ["SCALAR_MEASURE_ROWS", "BatchTask"]

SCALAR_MEASURE_ROWS = 8
"""Sub-envs whose goals switched on a tick are measured again by the measurement rule on
floats, one by one, up to this many (random three-rod scenes switch a few per step); more
take one pass of the rule on arrays."""


def readings(rows: list[list[float]]) -> list[BodyReading]:
    """Per body (position, orientation, velocity, angular velocity) tuples from 13-float rows."""
    return [(tuple(r[0:3]), tuple(r[3:7]), tuple(r[7:10]), tuple(r[10:13])) for r in rows]


_LAST_FIRST = {n: (n - 1, *range(n - 1)) for n in range(1, 6)}


def _cols(a: np.ndarray) -> tuple:
    """The components of (..., k) arrays: k views (...), the form the rules take (a transpose
    with a fixed order: ``np.moveaxis`` costs several times more)."""
    return tuple(a.transpose(_LAST_FIRST[a.ndim]))


def _parts(state: np.ndarray) -> tuple:
    """(position, orientation, velocity, angular velocity) of (..., 13) states."""
    c = _cols(state)
    return c[0:3], c[3:7], c[7:10], c[10:13]


class BatchTask:
    """The arrays and per-step rules of N plain ``SGCEnv`` sub-envs (module docstring)."""

    def __init__(self, envs: list[SGCEnv]) -> None:
        first = envs[0]
        self.envs = envs
        n, b = len(envs), first._n
        self.n, self.b = n, b
        self.size = first._block_end
        self.record_size = first._record.size // 8
        self.use_torque = first.use_torque
        self.coef = list(first._actuation._coef)
        self.reward = first._reward
        self.view = first._view
        z = np.zeros
        self.tick = z(n, dtype=np.int64)
        self.dt = z(n)
        self.max_steps = z(n, dtype=np.int64)
        self.state = z((n, b, 13))  # position, orientation (xyzw), velocity, angular velocity
        self.phi = z((n, b, 3))
        self.uid = z((n, b), dtype=np.int64)
        self.client = np.array([env.sim.client for env in envs])  # each sub-env's world
        self._clients = np.repeat(self.client, b).tolist()
        self._worlds = sorted(set(self.client.tolist()))
        self.flimit, self.mass = z((n, b)), z((n, b))
        self.tscale, self.gravity = z((n, b, 3)), z((n, 1, 3))
        self.lo, self.hi = z((n, 1, 3)), z((n, 1, 3))
        self.has_pos, self.has_ori = z((n, b), dtype=bool), z((n, b), dtype=bool)
        self.has_offset = z((n, b), dtype=bool)
        self.offset, self.offset_res, self.nail = z((n, b, 3)), z((n, b, 3)), z((n, b, 3))
        self.goal_q = z((n, b, 4))
        self.ptime, self.otime = z((n, b)), z((n, b))
        self.pcourse, self.ocourse = z((n, b, 13)), z((n, b, 13))
        self.goal_index = np.full((n, b), -1)
        self.orientation_goal_index = np.full((n, b), -1)
        self.next_event = z(n, dtype=np.int64)
        self.applied = z((n, 6 * b))
        # what measure() computes
        self.point, self.dev = z((n, b, 3)), z((n, b, 6))
        self.ptl, self.otl = z((n, b)), z((n, b))
        self.failed, self.spin = z(n, dtype=bool), z(n, dtype=bool)
        self.rec = z((n, self.record_size))
        self.view_constants = np.stack([env._view_constants for env in envs])
        self.obs = self.view.observe(self.rec, self.view_constants)
        self._shared = False
        self.props: list[int] = []
        self._uids: list[int] = []
        for i in range(n):
            self.load(i)

    # ---------------------------------------------------------------- sub-env objects

    def load(self, i: int, record: bool = True) -> None:
        """Read sub-env ``i``'s state from its ``SGCEnv`` (and its record and observation into
        this step's buffers unless ``record`` is False)."""
        env = self.envs[i]
        task, act = env.task, env._actuation
        self.tick[i] = env._tick
        self.dt[i] = env.dt
        self.max_steps[i] = env.max_steps
        self.state[i] = [(*p, *o, *v, *w) for p, o, v, w in env._states]
        self.phi[i] = [tuple(p) for p in task.phi]
        if self.uid[i].tolist() != env._uids:
            self.uid[i] = env._uids
            self._uids = []
        self.flimit[i], self.mass[i] = act._flimit, act._mass
        self.tscale[i], self.gravity[i, 0] = act._tscale, act._gravity
        self.lo[i, 0], self.hi[i, 0] = env._ws_low, env._ws_high
        self.has_pos[i], self.has_ori[i] = task.has_position, task.has_orientation
        self.applied[i] = env._applied
        self.point[i], self.dev[i] = task.points, task.deviations
        self.ptl[i], self.otl[i] = task.position_time_left, task.orientation_time_left
        self.failed[i], self.spin[i] = env._failed, env._spin_clamped
        has_props = bool(env._prop_uids)
        if has_props != (i in self.props):
            self.props = sorted({*self.props, i} if has_props else set(self.props) - {i})
        self.view_constants[i] = env._view_constants
        self.load_goals(i)
        if record:
            if self._shared:  # handed out: later loads must not change them
                self.rec, self.obs = self.rec.copy(), self.obs.copy()
                self._shared = False
            size = self.size
            self.rec[i, : size - 1] = env._block.ravel()
            self.rec[i, size - 1] = env._tick * env.dt
            self.rec[i, size:] = env._tail.ravel()
            self.obs[i] = env._obs

    def load_goals(self, i: int) -> None:
        """Copy sub-env ``i``'s current goals (what ``GoalTask`` caches per goal)."""
        task = self.envs[i].task
        self.offset[i] = task.offsets
        self.has_offset[i] = task.has_offset
        self.offset_res[i] = task.offset_residuals
        self.nail[i] = task.nails
        self.goal_q[i] = task.goal_quaternions
        self.ptime[i], self.otime[i] = task.position_goal_time, task.orientation_goal_time
        self.pcourse[i], self.ocourse[i] = task.position_course, task.orientation_course
        self.goal_index[i] = task.goal_index
        self.orientation_goal_index[i] = task.orientation_goal_index
        self.next_event[i] = task.next_event

    def sync(self, i: int) -> None:
        """Write sub-env ``i``'s state into its ``SGCEnv``, as its own step would have left it."""
        env, task = self.envs[i], self.envs[i].task
        env._tick = int(self.tick[i])
        env._states = readings(self.state[i].tolist())
        task.points = list(map(tuple, self.point[i].tolist()))
        task.deviations = list(map(tuple, self.dev[i].tolist()))
        task.phi = list(map(tuple, self.phi[i].tolist()))
        task.position_time_left = self.ptl[i].tolist()
        task.orientation_time_left = self.otl[i].tolist()
        task.time = env._tick * env.dt
        env._applied = self.applied[i].tolist()
        record = self.rec[i].copy()
        size = self.size
        env._obs = self.obs[i].copy()
        env._block = record[: size - 1].reshape(self.b, BODY_BLOCK_SIZE)
        env._tail = record[size:].reshape(3, self.b, 3)
        env._failed, env._spin_clamped = bool(self.failed[i]), bool(self.spin[i])

    def share(self) -> tuple[np.ndarray, np.ndarray]:
        """This step's observation and record buffers, handed out (later loads copy them)."""
        self._shared = True
        return self.obs, self.rec

    # ---------------------------------------------------------------- one control step

    def step(
        self, rows: list[int], values: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, dict[int, list[GoalEvent]]]:
        """One control step of sub-envs ``rows`` (their clipped actions, float64): drives,
        physics, measure, goal switches, flags, reward, record and observation. Returns the
        rewards, terminated flags, ``tick >= max_steps`` and the goal events (by sub-env);
        rows not stepped hold stale values until they are loaded."""
        n = self.n
        every = len(rows) == n
        sel: Any = slice(None) if every else np.asarray(rows, dtype=np.intp)
        actions = np.zeros((n, values.shape[1]))
        actions[sel] = values
        with np.errstate(all="ignore"):
            forces, torques, paths = self._drives(actions)
        self._physics(rows, sel, forces, torques, paths)
        self.tick[sel] += 1
        with np.errstate(all="ignore"):
            self.measure(sel)
            events = self._advance(rows)
            self._flags(sel)
            rewards = self._rewards(actions, events)
            self._record()
        return rewards, self.failed.copy(), self.tick >= self.max_steps, events

    def _drives(self, actions: np.ndarray) -> tuple[np.ndarray, np.ndarray | None, np.ndarray]:
        """The actuation rule on every sub-env: forces and torques (N, bodies, 3; torques
        None without them), the CoM paths (substeps, N, bodies, 3); sets the applied record."""
        n, b = self.n, self.b
        a = _cols(actions.reshape(n, b, 6 if self.use_torque else 3))
        pos, orn, lin, _ = _parts(self.state)
        force, torque, path = body_drive(
            a, pos, orn, lin, self.flimit, _cols(self.tscale), self.mass, _cols(self.gravity),
            self.coef,
        )  # fmt: skip
        forces = np.stack(force, axis=-1)
        self.applied[:, : 3 * b] = forces.reshape(n, -1)
        torques = None
        if torque is not None:
            torques = np.stack(torque, axis=-1)
            self.applied[:, 3 * b :] = torques.reshape(n, -1)
        else:
            self.applied[:, 3 * b :] = 0.0
        return forces, torques, np.stack([np.stack(p, axis=-1) for p in path])

    def _physics(
        self,
        rows: list[int],
        sel: Any,
        forces: np.ndarray,
        torques: np.ndarray | None,
        paths: np.ndarray,
    ) -> None:
        """The world's substeps with the rows' drives, the props placed, then one read of the
        rows' bodies (the calls of ``Simulator.step_bodies`` and ``body_states``, by ``map``)."""
        pb = pybullet
        every = len(rows) == self.n
        if every:
            if not self._uids:
                self._uids = self.uid.ravel().tolist()
            uids, clients = self._uids, self._clients
            worlds = self._worlds
        else:
            uids = self.uid[sel].ravel().tolist()
            clients = np.repeat(self.client[sel], self.b).tolist()
            worlds = sorted(set(self.client[sel].tolist()))
        count = len(uids)
        if not count:
            return
        minus, world = [-1] * count, [pb.WORLD_FRAME] * count
        f = forces[sel].reshape(-1, 3).tolist()
        tq = None if torques is None else torques[sel].reshape(-1, 3).tolist()
        p = paths[:, sel].reshape(len(paths), -1, 3).tolist()
        self._place_props(rows)
        force, torque, step = pb.applyExternalForce, pb.applyExternalTorque, pb.stepSimulation
        for pk in p:
            for _ in map(force, uids, minus, f, pk, world, clients):
                pass
            if tq is not None:
                for _ in map(torque, uids, minus, tq, world, clients):
                    pass
            for c in worlds:
                step(c)
        poses = map(pb.getBasePositionAndOrientation, uids, clients)
        speeds = map(pb.getBaseVelocity, uids, clients)
        read = [p + o + v + w for (p, o), (v, w) in zip(poses, speeds, strict=True)]
        self.state[sel] = np.array(read).reshape(-1, self.b, 13)

    def _place_props(self, rows: list[int]) -> None:
        """Each stepping sub-env's props where the single env leaves them after the step. Once
        per step, not per substep: in a shared world nothing collides (no collision shapes),
        so a prop's path between control ticks changes nothing, and props live in a client
        that is never stepped (``SharedWorld.props``)."""
        stepping = self.props if len(rows) == self.n else sorted(set(self.props) & set(rows))
        if not stepping:
            return
        substeps = len(self.coef)
        uids: list[int] = []
        spots: list[Any] = []
        homes: list[int] = []
        for i in stepping:
            env = self.envs[i]
            uids += env._prop_uids
            spots += env._props.at((int(self.tick[i]) + 1) * substeps)
            homes += [env.sim.prop_client] * len(env._prop_uids)  # type: ignore[attr-defined]
        identity = [(0.0, 0.0, 0.0, 1.0)] * len(uids)
        for _ in map(pybullet.resetBasePositionAndOrientation, uids, spots, identity, homes):
            pass

    def measure(self, sel: Any) -> None:
        """The measurement rule (:func:`~sgc_env.envs.measure.measure`) on the rows ``sel``."""
        state = _parts(self.state[sel])
        t = (self.tick[sel] * self.dt[sel])[:, None]
        point, dev, left, phi, oleft = measure(
            state, t, _cols(self.offset[sel]), self.has_offset[sel], _cols(self.nail[sel]),
            self.has_pos[sel], self.ptime[sel], _cols(self.goal_q[sel]), self.has_ori[sel],
            self.otime[sel], _cols(self.phi[sel]),
        )  # fmt: skip
        self.point[sel] = np.stack(np.broadcast_arrays(*point), axis=-1)
        self.dev[sel] = np.stack(np.broadcast_arrays(*dev, left), axis=-1)[..., :6]
        self.phi[sel] = np.stack(phi, axis=-1)
        self.ptl[sel], self.otl[sel] = left, oleft

    def _advance(self, rows: list[int]) -> dict[int, list[GoalEvent]]:
        """Each due sub-env's own ``GoalTask.advance`` (goal ticks are rare); the sub-envs
        whose goals changed are measured again, as ``SGCEnv._observe(read=False)`` does."""
        due = (self.tick >= self.next_event) & (self.next_event >= 0)
        if not due.any():
            return {}
        if len(rows) < self.n:
            stepping = np.zeros(self.n, dtype=bool)
            stepping[rows] = True
            due &= stepping
        events: dict[int, list[GoalEvent]] = {}
        changed = []
        for i in np.flatnonzero(due).tolist():
            task = self.envs[i].task
            task.deviations = list(map(tuple, self.dev[i].tolist()))
            task.phi = list(map(tuple, self.phi[i].tolist()))
            happened, moved = task.advance(int(self.tick[i]))
            if happened:
                events[i] = happened
            if moved:
                self.load_goals(i)
                self.phi[i] = task.phi
                changed.append(i)
            else:
                self.next_event[i] = task.next_event
        if len(changed) > SCALAR_MEASURE_ROWS:
            self.measure(np.asarray(changed, dtype=np.intp))
        else:  # the same rule on floats: an array pass over a few rows costs more
            for i in changed:
                task = self.envs[i].task
                task.measure(readings(self.state[i].tolist()), int(self.tick[i]) * self.envs[i].dt)
                self.point[i], self.dev[i] = task.points, task.deviations
                self.phi[i] = task.phi
                self.ptl[i], self.otl[i] = task.position_time_left, task.orientation_time_left
        return events

    def _flags(self, sel: Any) -> None:
        """The failure rule (:func:`~sgc_env.envs.failure.body_flags`) on the rows ``sel``."""
        ok, clamped = body_flags(_parts(self.state[sel]), _cols(self.lo[sel]), _cols(self.hi[sel]))
        self.failed[sel] = ~ok.all(axis=-1)
        self.spin[sel] = clamped.any(axis=-1)

    def tracks(self) -> list[TrackReading]:
        """Every body's tracks over the sub-envs, position first (the reward's order)."""
        out: list[TrackReading] = []
        for j in range(self.b):
            for has, d, left, course, floor in (
                (self.has_pos, self.dev, self.ptl, self.pcourse, POSITION_FLOOR),
                (self.has_ori, self.phi, self.otl, self.ocourse, ORIENTATION_FLOOR),
            ):
                out.append((has[:, j], _cols(d[:, j]), left[:, j], _cols(course[:, j]), floor))
        return out

    def _rewards(self, actions: np.ndarray, events: dict[int, list[GoalEvent]]) -> np.ndarray:
        """The env's reward mode, scored on every sub-env at once."""
        bonus = np.zeros(self.n)
        for i, happened in events.items():
            bonus[i] = goal_bonus(happened)
        score = StepScore(
            self.tracks(), self.b, square_sum(actions), actions.shape[1], bonus, self.failed,
            self.max_steps - self.tick,
        )  # fmt: skip
        return np.broadcast_to(self.reward.reward(score), (self.n,)).astype(np.float64)

    def _record(self) -> None:
        """This step's record (N, record) and observation (the view's), in fresh buffers."""
        n, b, size = self.n, self.b, self.size
        rec = np.empty((n, self.record_size))
        entries = body_block(
            _parts(self.state), _cols(self.offset), _cols(self.dev), self.ptl,
            _cols(self.pcourse), _cols(self.phi), self.otl, _cols(self.ocourse),
            _cols(self.offset_res),
        )  # fmt: skip
        rec[:, : size - 1] = pack_blocks(entries, (n, b)).reshape(n, -1)
        rec[:, size - 1] = self.tick * self.dt
        rec[:, size : size + 3 * b] = self.point.reshape(n, -1)
        rec[:, size + 3 * b :] = self.applied
        self.rec = rec
        self.obs = self.view.observe(rec, self.view_constants)
        self._shared = False
