"""The per-step task of every sub-env of a batch at once: the single env's rules on arrays.

Why: with N sub-envs in one world the physics is a small part of a step; the rest would be N
times the single env's per-body Python. :class:`BatchTask` holds every sub-env's state in
arrays and calls the very rules the single env calls, with arrays over (bodies, sub-envs)
where the single env passes one body's floats: actuation
(:func:`~sgc_env.envs.actuation.body_drive`),
measurement (:func:`~sgc_env.envs.measure.measure`), failure
(:func:`~sgc_env.envs.failure.body_flags`), the reward mode (its one ``reward`` method), the
step record (:func:`~sgc_env.envs.record.body_block`) and the observation view. Goal switching
is rare and stays each sub-env's own :meth:`~sgc_env.envs.task.GoalTask.advance`, its new goal
copied into the arrays afterwards; so do resets and pushes.

The arrays are component-major, (components, bodies, sub-envs): a vector's component is one
contiguous (bodies, sub-envs) block, the form the rules take. Why: the rules' arithmetic is a
few hundred numpy calls on small arrays, and a call on contiguous operands costs about half
what it costs on the strided columns of (sub-envs, bodies, components) arrays.

The sub-env objects are not updated on every step: :meth:`sync` writes a sub-env's state back
into its ``SGCEnv`` and places its props (the batch does so before handing the sub-envs out;
nothing reads a prop between, see :meth:`sync`) and :meth:`load`
reads it from there (after a reset, or once the sub-envs were handed out and may have been
pushed). The record (N, record) and observation (N, obs) buffers are fresh every step, so
observations and infos handed out earlier keep their values; a :meth:`load` into buffers
already handed out copies them first.
"""

from __future__ import annotations

from itertools import chain
from typing import Any

import numpy as np

from sgc_env.observation import BODY_BLOCK_SIZE
from sgc_env.paper.elementwise import any_
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


def _parts(state: np.ndarray) -> tuple:
    """(position, orientation, velocity, angular velocity) of (13, ...) states, each a tuple
    of component views."""
    c = tuple(state)
    return c[0:3], c[3:7], c[7:10], c[10:13]


_VECTORS = ("offset", "nail", "goal_q", "phi", "dev", "pcourse", "ocourse", "offset_res",
            "tscale", "gravity", "lo", "hi")  # fmt: skip
_SCALARS = ("has_offset", "has_pos", "has_ori", "ptime", "otime", "ptl", "otl", "flimit", "mass")


def _put(store: np.ndarray, values: Any, sel: Any) -> None:
    """Write a rule's components (arrays over (bodies, rows), or floats) into the rows ``sel``
    of a (components, bodies, sub-envs) array."""
    if sel.__class__ is slice:  # every row
        for row, value in zip(store, values, strict=True):
            row[...] = value
    else:
        for row, value in zip(store, values, strict=True):
            row[:, sel] = value


def _column(store: np.ndarray, i: int) -> list[Any]:
    """Sub-env ``i``'s per-body tuples of a (components, bodies, sub-envs) array."""
    return list(map(tuple, store[..., i].T.tolist()))


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
        self.substeps = first.substeps
        # One pair of (substeps, 1, 1) arrays: the rule's path over every substep in one pass.
        kh, c = (
            np.array(column)[:, None, None] for column in zip(*first._actuation._coef, strict=True)
        )
        self.coef = [(kh, c)]
        self.reward = first._reward
        self.view = first._view
        z = np.zeros
        self.tick = z(n, dtype=np.int64)
        self.dt = z(n)
        self.max_steps = z(n, dtype=np.int64)
        self.state = z((13, b, n))  # position, orientation (xyzw), velocity, angular velocity
        self.phi = z((3, b, n))
        self.uid = z((n, b), dtype=np.int64)
        self.client = np.array([env.sim.client for env in envs])  # each sub-env's world
        self._clients = np.tile(self.client, b).tolist()  # the physics' order: body-major
        self._worlds = sorted(set(self.client.tolist()))
        self.flimit, self.mass = z((b, n)), z((b, n))
        self.tscale, self.gravity = z((3, b, n)), z((3, n))
        self.lo, self.hi = z((3, n)), z((3, n))
        self.has_pos, self.has_ori = z((b, n), dtype=bool), z((b, n), dtype=bool)
        self.has_offset = z((b, n), dtype=bool)
        self.offset, self.offset_res, self.nail = z((3, b, n)), z((3, b, n)), z((3, b, n))
        self.goal_q = z((4, b, n))
        self.ptime, self.otime = z((b, n)), z((b, n))
        self.pcourse, self.ocourse = z((13, b, n)), z((13, b, n))
        self.goal_index = np.full((n, b), -1)  # as infos hand them out
        self.orientation_goal_index = np.full((n, b), -1)
        self.next_event = z(n, dtype=np.int64)
        self.applied = z((n, 6 * b))  # as the record holds it
        # what measure() computes
        self.point, self.dev = z((3, b, n)), z((6, b, n))
        self.ptl, self.otl = z((b, n)), z((b, n))
        self.failed, self.spin = z(n, dtype=bool), z(n, dtype=bool)
        self.rec = z((n, self.record_size))
        self.view_constants = np.stack([env._view_constants for env in envs])
        self.obs = self.view.observe(self.rec, self.view_constants)
        self._shared = False
        self._uids: list[int] = []
        self._tracks: list[TrackReading] = []
        # The rules' operands when every sub-env steps, built once: the arrays are written in
        # place, never replaced, so their component views stay theirs.
        self._whole: dict[str, Any] = {name: tuple(getattr(self, name)) for name in _VECTORS}
        self._whole.update((name, getattr(self, name)) for name in _SCALARS)
        self._whole["state"] = _parts(self.state)
        for i in range(n):
            self.load(i)

    def _take(self, name: str, sel: Any) -> Any:
        """Array ``name`` on the rows ``sel``: its component views when every row steps (a
        slice), else a copy of the rows (a vector's components as its first axis)."""
        if sel.__class__ is slice:
            return self._whole[name]
        if name == "state":
            return _parts(self.state[..., sel])
        return getattr(self, name)[..., sel]

    # ---------------------------------------------------------------- sub-env objects

    def load(self, i: int, record: bool = True) -> None:
        """Read sub-env ``i``'s state from its ``SGCEnv`` (and its record and observation into
        this step's buffers unless ``record`` is False)."""
        env = self.envs[i]
        task, act = env.task, env._actuation
        self.tick[i] = env._tick
        self.dt[i] = env.dt
        self.max_steps[i] = env.max_steps
        self.state[..., i].T[...] = [(*p, *o, *v, *w) for p, o, v, w in env._states]
        self.phi[..., i].T[...] = task.phi
        if self.uid[i].tolist() != env._uids:
            self.uid[i] = env._uids
            self._uids = []
        self.flimit[:, i], self.mass[:, i] = act._flimit, act._mass
        self.tscale[..., i].T[...] = act._tscale
        self.gravity[:, i] = act._gravity
        self.lo[:, i], self.hi[:, i] = env._ws_low, env._ws_high
        self.has_pos[:, i], self.has_ori[:, i] = task.has_position, task.has_orientation
        self.applied[i] = env._applied
        self.point[..., i].T[...] = task.points
        self.dev[..., i].T[...] = task.deviations
        self.ptl[:, i], self.otl[:, i] = task.position_time_left, task.orientation_time_left
        self.failed[i], self.spin[i] = env._failed, env._spin_clamped
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
        self.offset[..., i].T[...] = task.offsets
        self.has_offset[:, i] = task.has_offset
        self.offset_res[..., i].T[...] = task.offset_residuals
        self.nail[..., i].T[...] = task.nails
        self.goal_q[..., i].T[...] = task.goal_quaternions
        self.ptime[:, i], self.otime[:, i] = task.position_goal_time, task.orientation_goal_time
        self.pcourse[..., i].T[...] = task.position_course
        self.ocourse[..., i].T[...] = task.orientation_course
        self.goal_index[i] = task.goal_index
        self.orientation_goal_index[i] = task.orientation_goal_index
        self.next_event[i] = task.next_event

    def sync(self, i: int) -> None:
        """Write sub-env ``i``'s state into its ``SGCEnv``, as its own step would have left it,
        its props included. Why the props only here: in a shared world they touch nothing (no
        collision shapes, a client of their own that is never stepped), so nothing reads them
        between steps, and placing them on every step cost more than the rest of the step of
        a three-rod batch."""
        env, task = self.envs[i], self.envs[i].task
        env._tick = int(self.tick[i])
        env._states = readings(self.state[..., i].T.tolist())
        task.points = _column(self.point, i)
        task.deviations = _column(self.dev, i)
        task.phi = _column(self.phi, i)
        task.position_time_left = self.ptl[:, i].tolist()
        task.orientation_time_left = self.otl[:, i].tolist()
        task.time = env._tick * env.dt
        env._applied = self.applied[i].tolist()
        record = self.rec[i].copy()
        size = self.size
        env._obs = self.obs[i].copy()
        env._block = record[: size - 1].reshape(self.b, BODY_BLOCK_SIZE)
        env._tail = record[size:].reshape(3, self.b, 3)
        env._failed, env._spin_clamped = bool(self.failed[i]), bool(self.spin[i])
        if env._prop_uids:  # where the single env's step leaves them
            for uid, spot in zip(env._prop_uids, env._props.at(env._tick * self.substeps),
                                 strict=True):  # fmt: skip
                env.sim.move(uid, spot)

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
        if every:
            actions = values
        else:
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
        """The actuation rule on every sub-env: forces and torques (3, bodies, N; torques
        None without them), the CoM paths (3, substeps, bodies, N); sets the applied record."""
        n, b = self.n, self.b
        a = np.ascontiguousarray(actions.reshape(n, b, -1).transpose(2, 1, 0))
        pos, orn, lin, _ = self._whole["state"]
        w = self._whole
        force, torque, path = body_drive(
            tuple(a), pos, orn, lin, self.flimit, w["tscale"], self.mass, w["gravity"], self.coef
        )
        forces = np.array(force)
        applied = self.applied.reshape(n, 2, b, 3)
        applied[:, 0] = forces.T
        torques = None
        if torque is not None:
            torques = np.array(torque)
            applied[:, 1] = torques.T
        else:
            applied[:, 1] = 0.0
        return forces, torques, np.array(path[0])

    def _physics(
        self,
        rows: list[int],
        sel: Any,
        forces: np.ndarray,
        torques: np.ndarray | None,
        paths: np.ndarray,
    ) -> None:
        """The world's substeps with the rows' drives, then one read of the rows' bodies (the
        calls of ``Simulator.step_bodies`` and ``body_states``, by ``map``), body-major: the
        arrays' order (the order of calls for different bodies changes nothing)."""
        pb = pybullet
        b = self.b
        every = len(rows) == self.n
        if every:
            if not self._uids:
                self._uids = self.uid.T.ravel().tolist()
            uids, clients = self._uids, self._clients
            worlds = self._worlds
        else:
            uids = self.uid[sel].T.ravel().tolist()
            clients = np.tile(self.client[sel], b).tolist()
            worlds = sorted(set(self.client[sel].tolist()))
        count = len(uids)
        if not count:
            return
        minus, world = [-1] * count, [pb.WORLD_FRAME] * count
        f = forces[..., sel].reshape(3, count).T.tolist()
        tq = None if torques is None else torques[..., sel].reshape(3, count).T.tolist()
        p = paths[..., sel].reshape(3, self.substeps, count).transpose(1, 2, 0).tolist()
        force, torque, step = pb.applyExternalForce, pb.applyExternalTorque, pb.stepSimulation
        for pk in p:
            for _ in map(force, uids, minus, f, pk, world, clients):
                pass
            if tq is not None:
                for _ in map(torque, uids, minus, tq, world, clients):
                    pass
            for c in worlds:
                step(c)
        flat = chain.from_iterable  # the floats of every (position, orientation) pair, in turn
        poses = flat(flat(map(pb.getBasePositionAndOrientation, uids, clients)))
        speeds = flat(flat(map(pb.getBaseVelocity, uids, clients)))
        pose = np.fromiter(poses, np.float64, 7 * count).reshape(count, 7)
        speed = np.fromiter(speeds, np.float64, 6 * count).reshape(count, 6)
        self.state[0:7][..., sel] = pose.T.reshape(7, b, -1)
        self.state[7:13][..., sel] = speed.T.reshape(6, b, -1)

    def measure(self, sel: Any) -> None:
        """The measurement rule (:func:`~sgc_env.envs.measure.measure`) on the rows ``sel``."""
        t = self.tick[sel] * self.dt[sel]
        take = self._take
        point, dev, left, phi, oleft = measure(
            take("state", sel), t, take("offset", sel), take("has_offset", sel),
            take("nail", sel), take("has_pos", sel), take("ptime", sel), take("goal_q", sel),
            take("has_ori", sel), take("otime", sel), take("phi", sel),
        )  # fmt: skip
        _put(self.point, point, sel)
        _put(self.dev, dev, sel)
        _put(self.phi, phi, sel)
        self.ptl[:, sel], self.otl[:, sel] = left, oleft

    def _advance(self, rows: list[int]) -> dict[int, list[GoalEvent]]:
        """Each due sub-env's own ``GoalTask.advance`` (goal ticks are rare); the sub-envs
        whose goals changed are measured again, as ``SGCEnv._observe(read=False)`` does."""
        due = (self.tick >= self.next_event) & (self.next_event >= 0)
        if not any_(due):
            return {}
        if len(rows) < self.n:
            stepping = np.zeros(self.n, dtype=bool)
            stepping[rows] = True
            due &= stepping
        events: dict[int, list[GoalEvent]] = {}
        changed = []
        for i in np.flatnonzero(due).tolist():
            task = self.envs[i].task
            task.deviations = _column(self.dev, i)
            task.phi = _column(self.phi, i)
            happened, moved = task.advance(int(self.tick[i]))
            if happened:
                events[i] = happened
            if moved:
                self.load_goals(i)
                changed.append(i)
            else:
                self.next_event[i] = task.next_event
        if len(changed) > SCALAR_MEASURE_ROWS:
            for i in changed:  # phi moved on with the goal: the rule unwraps next to it
                self.phi[..., i].T[...] = self.envs[i].task.phi
            self.measure(np.asarray(changed, dtype=np.intp))
        else:  # the same rule on floats: an array pass over a few rows costs more
            for i in changed:
                task = self.envs[i].task
                states = readings(self.state[..., i].T.tolist())
                task.measure(states, int(self.tick[i]) * self.envs[i].dt)
                self.point[..., i].T[...] = task.points
                self.dev[..., i].T[...] = task.deviations
                self.phi[..., i].T[...] = task.phi
                self.ptl[:, i] = task.position_time_left
                self.otl[:, i] = task.orientation_time_left
        return events

    def _flags(self, sel: Any) -> None:
        """The failure rule (:func:`~sgc_env.envs.failure.body_flags`) on the rows ``sel``."""
        take = self._take
        ok, clamped = body_flags(take("state", sel), take("lo", sel), take("hi", sel))
        self.failed[sel] = ~ok.all(axis=0)
        self.spin[sel] = clamped.any(axis=0)

    def tracks(self) -> list[TrackReading]:
        """Every body's tracks over the sub-envs, position first (the reward's order): views
        of the arrays, built once."""
        if not self._tracks:
            for j in range(self.b):
                self._tracks.append((self.has_pos[j], tuple(self.dev[:, j]), self.ptl[j],
                                     tuple(self.pcourse[:, j]), POSITION_FLOOR))  # fmt: skip
                self._tracks.append((self.has_ori[j], tuple(self.phi[:, j]), self.otl[j],
                                     tuple(self.ocourse[:, j]), ORIENTATION_FLOOR))  # fmt: skip
        return self._tracks

    def _rewards(self, actions: np.ndarray, events: dict[int, list[GoalEvent]]) -> np.ndarray:
        """The env's reward mode, scored on every sub-env at once."""
        bonus = np.zeros(self.n)
        for i, happened in events.items():
            bonus[i] = goal_bonus(happened)
        score = StepScore(
            self.tracks(), self.b, square_sum(actions), actions.shape[1], bonus, self.failed,
            self.max_steps - self.tick,
        )  # fmt: skip
        reward = self.reward.reward(score)
        if reward.__class__ is np.ndarray and reward.shape == (self.n,):
            return reward.astype(np.float64)  # a copy: the mode's array may be kept elsewhere
        return np.broadcast_to(reward, (self.n,)).astype(np.float64)

    def _record(self) -> None:
        """This step's record (N, record) and observation (the view's), in fresh buffers."""
        n, b, size = self.n, self.b, self.size
        rec = np.empty((n, self.record_size))
        w = self._whole
        entries = body_block(
            w["state"], w["offset"], w["dev"], self.ptl, w["pcourse"], w["phi"], self.otl,
            w["ocourse"], w["offset_res"],
        )  # fmt: skip
        pack_blocks(entries, rec[:, : size - 1].reshape(n, b, BODY_BLOCK_SIZE))
        rec[:, size - 1] = self.tick * self.dt
        rec[:, size : size + 3 * b].reshape(n, b, 3)[...] = self.point.T
        rec[:, size + 3 * b :] = self.applied
        self.rec = rec
        self.obs = self.view.observe(rec, self.view_constants)
        self._shared = False
