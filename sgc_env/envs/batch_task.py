"""The per-step task work of every sub-env of a batch at once, in numpy over sub-envs.

Why: with N sub-envs in one world the physics is a small part of a step; the rest was N
times the single env's per-body Python (``_observe``, ``GoalTask.measure``, the reward,
``Actuation.drives``, the info). :class:`BatchTask` holds every sub-env's state in
(N, bodies, ...) arrays and repeats that work on them, operation for operation in the scalar
code's order (:mod:`.batch_math`), so that each sub-env's observation, reward, flags, drives
and info equal the single env's bit for bit (tests/sgc_env/envs/test_batch.py compares them on every
id and reward mode). It is a second implementation of the scalar task; what stays scalar is
what is rare: goal switching (``GoalTask.advance`` on goal ticks, its new goal copied into
the arrays afterwards), resets, pushes and the props' moves.

The sub-env objects are not updated on every step: :meth:`sync` writes a sub-env's state back
into its ``SGCEnv`` (the batch does so before handing the sub-envs out) and :meth:`load`
reads it from there (after a reset, or once the sub-envs were handed out and may have been
pushed). The record (N, record) and observation (N, obs) buffers are fresh every step, so
observations and infos handed out earlier keep their values; a :meth:`load` into buffers
already handed out copies them first.
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from typing import Any

import numpy as np

from sgc_env.observation import BODY_BLOCK_SIZE, ObservationLayout
from sgc_env.paper import quaternion
from sgc_env.simulator import BodyReading, pybullet

from . import batch_math as bm
from .rewards import (
    EFFORT_WEIGHT,
    ORIENTATION_FLOOR,
    POSITION_FLOOR,
    TRACK_COST_CAP,
    goal_bonus,
)  # fmt: skip
from .sgc_env import MAX_SPEED, SPIN_CLAMP, SGCEnv
from .task import GoalEvent

__all__ = ["BatchTask"]

_L = ObservationLayout(1)


def _col(name: str) -> int:
    return _L.body_slice(0, name).start


# Body-block columns (one block per body: state 0:13, then the fields of BODY_FIELDS).
_OFF, _DEV, _PV = _col("point_offset"), _col("position_deviation"), _col("point_velocity")
_PTL, _PC = _col("position_time_left"), _col("position_course_start")
_PHI, _OTL = _col("orientation_deviation"), _col("orientation_time_left")
_OC = _col("orientation_course_start")
_RES, _ORES = _col("position_deviation_residual"), _col("point_offset_residual")
assert (_OFF, _DEV, _PV, _PTL, _PC, _PHI, _OTL, _OC, _RES, _ORES, BODY_BLOCK_SIZE) == (
    13,
    16,
    19,
    22,
    23,
    36,
    39,
    40,
    53,
    74,
    77,
), "the observation layout changed: update BatchTask's record"

_YZX, _ZXY = [1, 2, 0], [2, 0, 1]
# The scalar quaternion rotation, applied to tuples of arrays (its arithmetic is elementwise):
# on the few-element arrays of a step, per-component operations beat gathers.
rotate: Callable[..., Any] = quaternion.rotate


def readings(rows: list[list[float]]) -> list[BodyReading]:
    """Per body (position, orientation, velocity, angular velocity) tuples from 13-float rows."""
    return [(tuple(r[0:3]), tuple(r[3:7]), tuple(r[7:10]), tuple(r[10:13])) for r in rows]


_SEQUENTIAL_SUM = sys.version_info < (3, 12)  # 3.12's sum() of floats is compensated


class BatchTask:
    """The arrays and per-step arithmetic of N plain ``SGCEnv`` sub-envs (module docstring)."""

    def __init__(self, envs: list[SGCEnv]) -> None:
        first = envs[0]
        self.envs = envs
        n, b = len(envs), first._n
        self.n, self.b = n, b
        self.size = first._obs_size
        self.record_size = first._record.size // 8
        self.use_torque = first.use_torque
        self.coef = list(first._actuation._coef)
        self.mode = first.reward_mode
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
        self.goal_factors = z((4, n, b, 4))  # bm.conjugate_factors of goal_q
        self.ptime, self.otime = z((n, b)), z((n, b))
        self.pcourse, self.ocourse = z((n, b, 13)), z((n, b, 13))
        self.goal_index = np.full((n, b), -1)
        self.orientation_goal_index = np.full((n, b), -1)
        self.next_event = z(n, dtype=np.int64)
        self.applied = z((n, 6 * b))
        # what measure() computes
        self.lever, self.point, self.dev = z((n, b, 3)), z((n, b, 3)), z((n, b, 6))
        self.ptl, self.otl = z((n, b)), z((n, b))
        self.failed, self.spin = z(n, dtype=bool), z(n, dtype=bool)
        self.rec = z((n, self.record_size))
        self.obs = z((n, self.size), dtype=np.float32)
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
        self.has_offset[i] = [o != (0.0, 0.0, 0.0) for o in task.offsets]
        self.offset_res[i] = task.offset_residuals
        self.nail[i] = task.nails
        self.goal_q[i] = task.goal_quaternions
        self.goal_factors[:, i] = bm.conjugate_factors(self.goal_q[i])
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
        physics, measure, goal switches, record and observation. Returns the rewards,
        terminated flags, ``tick >= max_steps`` and the goal events (by sub-env); rows not
        stepped hold stale values until they are loaded."""
        n = self.n
        every = len(rows) == n
        sel: Any = slice(None) if every else np.asarray(rows, dtype=np.intp)
        actions = np.zeros((n, values.shape[1]))
        actions[sel] = values
        with np.errstate(all="ignore"):
            forces, torques, paths, applied = self._drives(actions)
        self._physics(rows, sel, forces, torques, paths)
        self.tick[sel] += 1
        self.applied[sel] = applied[sel]
        with np.errstate(all="ignore"):
            self.measure(sel)
            events = self._advance(rows)
            self._flags(sel)
            rewards = self._rewards(actions, events)
            self._record()
        return rewards, self.failed.copy(), self.tick >= self.max_steps, events

    def _drives(
        self, actions: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray | None, np.ndarray, np.ndarray]:
        """``Actuation.drives`` of every sub-env: forces, torques (or None), CoM paths
        (substeps, N, bodies, 3) and the applied record (N, 6 * bodies)."""
        n, b = self.n, self.b
        a = actions.reshape(n, b, 6 if self.use_torque else 3)
        forces = a[..., 0:3] * self.flimit[..., None]
        s = self.state
        applied = np.empty((n, 6 * b))
        applied[:, : 3 * b] = forces.reshape(n, -1)
        torques = None
        if self.use_torque:
            x, y, z, w = s[..., 3], s[..., 4], s[..., 5], s[..., 6]
            bx, by, bz = rotate((-x, -y, -z, w), (a[..., 3], a[..., 4], a[..., 5]))
            sc = self.tscale
            torques = np.empty((n, b, 3))
            torques[..., 0], torques[..., 1], torques[..., 2] = rotate(
                (x, y, z, w), (bx * sc[..., 0], by * sc[..., 1], bz * sc[..., 2])
            )
            applied[:, 3 * b :] = torques.reshape(n, -1)
        else:
            applied[:, 3 * b :] = 0.0
        acc = forces / self.mass[..., None] + self.gravity
        x0, v = s[..., 0:3], s[..., 7:10]
        paths = np.empty((len(self.coef), n, b, 3))
        for k, (kh, c) in enumerate(self.coef):
            np.add(x0 + kh * v, c * acc, out=paths[k])
        return forces, torques, paths, applied

    def _physics(
        self,
        rows: list[int],
        sel: Any,
        forces: np.ndarray,
        torques: np.ndarray | None,
        paths: np.ndarray,
    ) -> None:
        """The world's substeps with the rows' drives and props' moves, then one read of the
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
        moves = self._moves(rows)
        force, torque, step = pb.applyExternalForce, pb.applyExternalTorque, pb.stepSimulation
        for k, pk in enumerate(p):
            if moves:
                props, spots, homes = moves[k]
                for _ in map(pb.resetBasePositionAndOrientation, props, spots,
                             [(0.0, 0.0, 0.0, 1.0)] * len(props), homes):  # fmt: skip
                    pass
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

    def _moves(self, rows: list[int]) -> list[tuple[list[int], list[Any], list[int]]]:
        """Per substep, the props of the stepping sub-envs, their next positions and worlds."""
        stepping = self.props if len(rows) == self.n else sorted(set(self.props) & set(rows))
        if not stepping:
            return []
        out: list[tuple[list[int], list[Any], list[int]]] = []
        for k in range(len(self.coef)):
            uids: list[int] = []
            spots: list[Any] = []
            homes: list[int] = []
            for i in stepping:
                env = self.envs[i]
                uids += env._prop_uids
                spots += env._props.at(int(self.tick[i]) * len(self.coef) + k + 1)
                homes += [env.sim.client] * len(env._prop_uids)
            out.append((uids, spots, homes))
        return out

    def measure(self, sel: Any) -> None:
        """``GoalTask.measure`` of the rows ``sel``: tracked points, D and D', unwrapped phi,
        times left (see GoalTask). A branch all rows take skips the ``np.where``."""
        s = self.state[sel]
        t = (self.tick[sel] * self.dt[sel])[:, None]
        pos, q, ang = s[..., 0:3], s[..., 3:7], s[..., 10:13]
        lever = self.offset[sel]
        has_off = self.has_offset[sel]
        point = pos
        if has_off.any():
            turned = bm.rotate(q, lever)
            point = pos + turned
            if not has_off.all():
                turned = np.where(has_off[..., None], turned, lever)
                point = np.where(has_off[..., None], point, pos)
            lever = turned
        dev = np.empty(s.shape[:-1] + (6,))
        dev[..., 0:3] = point - self.nail[sel]
        # D' = v + omega x r, each component as GoalTask.measure sums it
        dev[..., 3:6] = s[..., 7:10] + ang[..., _YZX] * lever[..., _ZXY]
        dev[..., 3:6] -= ang[..., _ZXY] * lever[..., _YZX]
        has_pos = self.has_pos[sel]
        left = self.ptime[sel] - t
        if not has_pos.all():
            dev = np.where(has_pos[..., None], dev, 0.0)
            left = np.where(has_pos, left, 0.0)
        self.dev[sel], self.ptl[sel], self.point[sel] = dev, left, point
        has_ori = self.has_ori[sel]
        if not has_ori.any():
            self.otl[sel] = 0.0
            return
        factors = [f[sel] for f in self.goal_factors]
        phi = self.phi[sel]
        new = bm.unwrap_rotvec(bm.log(bm.mul_conjugate(q, factors)), phi)
        left = self.otime[sel] - t
        if not has_ori.all():
            new = np.where(has_ori[..., None], new, phi)
            left = np.where(has_ori, left, 0.0)
        self.phi[sel], self.otl[sel] = new, left

    def _advance(self, rows: list[int]) -> dict[int, list[GoalEvent]]:
        """``GoalTask.advance`` of the sub-envs on a goal tick (scalar: goal ticks are rare);
        a sub-env whose goal changed is measured again, as ``SGCEnv._observe(read=False)``,
        by its own ``GoalTask.measure`` (a numpy pass over a few rows costs more)."""
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
                changed.append(i)
            else:
                self.next_event[i] = task.next_event
        for i in changed:
            task = self.envs[i].task
            task.measure(readings(self.state[i].tolist()), int(self.tick[i]) * self.envs[i].dt)
            self.point[i], self.dev[i] = task.points, task.deviations
            self.phi[i] = [tuple(p) for p in task.phi]
            self.ptl[i], self.otl[i] = task.position_time_left, task.orientation_time_left
        return events

    def _flags(self, sel: Any) -> None:
        """Failure (outside the workspace, non-finite, too fast) and the spin-clamp flag."""
        s = self.state[sel]
        pos = s[..., 0:3]
        vx, vy, vz = s[..., 7], s[..., 8], s[..., 9]
        wx, wy, wz = s[..., 10], s[..., 11], s[..., 12]
        inside = ((self.lo[sel] < pos) & (pos < self.hi[sel])).all(axis=-1)
        slow = vx * vx + vy * vy + vz * vz < MAX_SPEED**2
        self.failed[sel] = ~(inside & slow).all(axis=-1)
        self.spin[sel] = (wx * wx + wy * wy + wz * wz >= SPIN_CLAMP**2).any(axis=-1)

    def _rewards(self, actions: np.ndarray, events: dict[int, list[GoalEvent]]) -> np.ndarray:
        """The reward mode of every sub-env (``rewards._ModeReward``), with its failure charge."""
        n, b = self.n, self.b
        cost: Any = 0.0
        worst: Any = 0.0
        if self.mode != "sparse":
            tracks = (
                (self.has_pos, self.dev, self.ptl, self.pcourse, POSITION_FLOOR),
                (self.has_ori, self.phi, self.otl, self.ocourse, ORIENTATION_FLOOR),
            )
            for j in range(b):  # tracks in tracks_of's order: body by body, position first
                for has_track, d, left, course, floor in tracks:
                    has = has_track[:, j]
                    if not has.any():
                        continue
                    value = self._cost(d[:, j], left[:, j], course[:, j], floor)
                    if has.all():
                        cost, worst = cost + value, worst + TRACK_COST_CAP
                    else:
                        cost = np.where(has, cost + value, cost)
                        worst = np.where(has, worst + TRACK_COST_CAP, worst)
        reward = -np.broadcast_to(cost, (n,)) / b - self._effort(actions) + self._bonus(events)
        if self.mode != "distance" and self.failed.any():
            charge = (worst / b + EFFORT_WEIGHT) * (self.max_steps - self.tick)
            reward = np.where(self.failed, reward - charge, reward)
        return reward

    def _cost(self, d: np.ndarray, left: np.ndarray, c: np.ndarray, floor: float) -> np.ndarray:
        """``schedule_cost`` or ``distance_cost`` of one track over the sub-envs."""
        scale = bm.at_least(bm.norm3(c[:, 0], c[:, 1], c[:, 2]), floor)
        if self.mode == "distance":
            return bm.norm3(d[:, 0], d[:, 1], d[:, 2]) / scale
        ahead = left >= 0.0
        if ahead.all():
            f = left / c[:, 3]
            e = [d[:, k] - c[:, k] * f for k in range(3)]
        elif not ahead.any():
            e = [d[:, k] - -c[:, 8 + k] * left for k in range(3)]
        else:
            f = left / c[:, 3]
            e = [d[:, k] - np.where(ahead, c[:, k] * f, -c[:, 8 + k] * left) for k in range(3)]
        return bm.at_most(bm.norm3(e[0], e[1], e[2]) / scale, TRACK_COST_CAP)

    def _effort(self, actions: np.ndarray) -> np.ndarray:
        """``EFFORT_WEIGHT * sum(x * x) / len``, summed left to right as Python's ``sum``."""
        squares = actions * actions
        if _SEQUENTIAL_SUM:
            total = squares[:, 0].copy()
            for k in range(1, squares.shape[1]):
                total += squares[:, k]
        else:
            total = np.array([sum(row) for row in squares.tolist()])
        return EFFORT_WEIGHT * total / squares.shape[1]

    def _bonus(self, events: dict[int, list[GoalEvent]]) -> np.ndarray:
        bonus = np.zeros(self.n)
        for i, happened in events.items():
            bonus[i] = goal_bonus(happened)
        return bonus

    def _record(self) -> None:
        """This step's record (N, observation doubles + points, forces, torques) and float32
        observation, in fresh buffers (the single env's ``_observe`` layout)."""
        n, b, size = self.n, self.b, self.size
        rec = np.empty((n, self.record_size))
        block = rec[:, : size - 1].reshape(n, b, BODY_BLOCK_SIZE)
        block[..., 0:13] = self.state
        block[..., _OFF : _OFF + 3] = self.offset
        block[..., _DEV : _DEV + 6] = self.dev
        block[..., _PTL] = self.ptl
        block[..., _PC : _PC + 13] = self.pcourse
        block[..., _PHI : _PHI + 3] = self.phi
        block[..., _OTL] = self.otl
        block[..., _OC : _OC + 13] = self.ocourse
        s = self.state
        exact = np.concatenate((self.dev, s[..., 3:7], s[..., 10:13], s[..., 7:10], self.phi,
                                self.ptl[..., None], self.otl[..., None]), axis=-1)  # fmt: skip
        block[..., _RES:_ORES] = exact - exact.astype(np.float32).astype(np.float64)
        block[..., _ORES : _ORES + 3] = self.offset_res
        rec[:, size - 1] = self.tick * self.dt
        rec[:, size : size + 3 * b] = self.point.reshape(n, -1)
        rec[:, size + 3 * b :] = self.applied
        self.rec = rec
        self.obs = rec[:, :size].astype(np.float32)
        self._shared = False
