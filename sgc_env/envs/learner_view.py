"""The learner's view: what the reward measures, as bounded entries of order 1.

The planner's observation (:mod:`sgc_env.observation`) carries absolute positions, seconds,
course starts and float32 precision residuals: what the exact expert needs, in the units it
plans in. A learner handed that has to discover through its network that the reward pays for
``D - D_sched`` (:mod:`sgc_env.envs.rewards`), from entries of very different scales. This view
hands it over. Per body and track (position of the tracked point, then orientation):

| entry | size | scale | why |
|---|---|---|---|
| on-schedule error ``D - D_sched`` | 3 | 0.05 m (rad), squashed | what the reward charges |
| its rate ``D' - D'_sched`` | 3 | 0.5 m/s (rad/s), squashed | the damping a tracker needs |
| schedule velocity ``D'_sched`` | 3 | 1 m/s (rad/s), squashed | feed-forward: the course's way |
| next course's schedule velocity | 3 | 1 m/s (rad/s), squashed | feed-forward across the goal |
| current goal relative to the body | 3 | 1 m (rad), squashed | a preview, as Fetch gives goals |
| next goal relative to the body | 3 | 1 m (rad), squashed | the preview one goal further |
| course time fraction ``t_left / T_i`` | 1 | [0, 1] | the phase of the course |
| time to the goal, to the next goal | 2 | s, clipped to [-1, 3] | goals as (time, position) |
| flags: has the track, on the last goal | 2 | {0, 1} | which entries mean something |

then per body the action that hovers it (``-m g / force_limit``, 3 entries in action units),
and once the episode's time fraction (Pardo et al.'s time feature: the episode is finite).
"Squashed" is ``c tanh(x / c)`` with ``c = 3``: linear near the schedule, where the
tolerances are (2 cm is 0.4 of a unit), bounded when a body is far off it, so an MLP is never
handed inputs of 20-100. No absolute positions, no precision residuals: a policy that must be
exact to 1e-15 (the expert) reads the planner's view of the same state, which every env hands
out as ``env.unwrapped.planner_observation()``.

The view is computed from the step's double-precision record (one row per sub-env) and the
sub-env's :meth:`LearnerView.constants` (the hovering action, the episode's length) by one
rule, :func:`_track`: on arrays for the batched env (N rows), on floats for one env, whose
per-course terms it caches from one goal switch to the next (numpy's per-call overhead dwarfs
one env's arithmetic). The same float operations and numpy's one tanh give the same bits.
"""

from __future__ import annotations

import operator
import struct
from collections.abc import Sequence
from typing import Any

import gymnasium as gym
import numpy as np

from sgc_env.observation import BODY_BLOCK_SIZE, ObservationLayout
from sgc_env.paper.elementwise import where

from .schedule import on_schedule
from .views import ObservationView, observation_view

__all__ = [
    "LEARNER_BODY_SIZE",
    "LearnerView",
    "LEARNER_TRACK_SIZE",
    "learner_bounds",
    "learner_observation",
    "learner_size",
]

SQUASH = 3.0
ERROR_SCALE = 0.05
RATE_SCALE = 0.5
VELOCITY_SCALE = 1.0
GOAL_SCALE = 1.0
TIME_LOW, TIME_HIGH = -1.0, 3.0
LEARNER_TRACK_SIZE = 6 * 3 + 1 + 2 + 2
LEARNER_BODY_SIZE = 2 * LEARNER_TRACK_SIZE + 3

Vec = Sequence[Any]  # components: floats for one env, arrays for the batch

_L = ObservationLayout(1)


def _start(name: str) -> int:
    return _L.body_slice(0, name).start


# Per track, the block columns its rule reads (component columns consecutive): the deviation,
# its rate, the time left, then the course entries, course start to flags (one run of columns).
_TRACK_COLUMNS = tuple(
    (_start(deviation), _start(rate), _start(f"{track}_time_left"),
     _start(f"{track}_course_start"))
    for track, deviation, rate in (
        ("position", "position_deviation", "point_velocity"),
        ("orientation", "orientation_deviation", "angular_velocity"),
    )
)  # fmt: skip
# course start, duration, next start, next duration, end velocity, flags
_COURSE_SIZE = 3 + 1 + 3 + 1 + 3 + 2
# The same columns as one fancy index for the batch, (2 tracks, 20): D, D', t, then the course.
_BATCH_COLUMNS = np.array(
    [
        [*range(d, d + 3), *range(r, r + 3), t, *range(c, c + _COURSE_SIZE)]
        for d, r, t, c in _TRACK_COLUMNS
    ]
)
_SCALES = np.array([ERROR_SCALE] * 3 + [RATE_SCALE] * 3 + [VELOCITY_SCALE] * 6 + [GOAL_SCALE] * 6)
_RAW = len(_SCALES)  # squashed entries per track


def learner_size(n_bodies: int) -> int:
    """Entries of the learner's view of ``n_bodies`` bodies."""
    return n_bodies * LEARNER_BODY_SIZE + 1


def learner_bounds(n_bodies: int) -> tuple[np.ndarray, np.ndarray]:
    """The view's tight bounds (float32): the squash bound, the clip ranges, [0, 1] and the
    hover action's range (an action is clipped to [-1, 1])."""
    track_low = [-SQUASH] * 18 + [0.0] + [TIME_LOW] * 2 + [0.0, 0.0]
    track_high = [SQUASH] * 18 + [1.0] + [TIME_HIGH] * 2 + [1.0, 1.0]
    body_low = track_low * 2 + [-1.0] * 3
    body_high = track_high * 2 + [1.0] * 3
    low = np.array(body_low * n_bodies + [0.0], dtype=np.float32)
    high = np.array(body_high * n_bodies + [1.0], dtype=np.float32)
    return low, high


def _clip(x: Any, low: float, high: float) -> Any:
    """``np.clip``'s values (NaN stays NaN; at a bound, the bound, as ``np.maximum`` and
    ``np.minimum`` give it) on an array, or on a float in plain Python."""
    if x.__class__ is np.ndarray:
        return np.minimum(np.maximum(x, low), high)
    x = low if x <= low else x
    return high if x >= high else x


def _pick(condition: Any, a: list[Any], b: list[Any]) -> list[Any]:
    """:func:`~sgc_env.paper.elementwise.where` of each component: one branch for a float
    condition, one ``np.where`` per component for an array."""
    if condition.__class__ is np.ndarray:
        return [np.where(condition, x, y) for x, y in zip(a, b, strict=True)]
    return a if condition else b


def _track(
    d: Vec, r: Vec, t: Any, c0: Vec, span: Any, c1: Vec, next_span: Any, v_end: Vec, has: Any,
    last: Any,
) -> tuple[list[Any], list[Any]]:  # fmt: skip
    """One track's rule (module table): its 18 entries before the squash (``D - D_sched``,
    ``D' - D'_sched``, ``D'_sched``, the next course's ``D'_sched``, the goal and the next
    goal relative to the body) and its last 5 (time fraction, times, flags).

    Written once for one env and for many (:mod:`sgc_env.paper.elementwise`): a vector is its
    3 components as floats (one track of one env) or one array whose last axis holds them (all
    tracks of all sub-envs, the scalars' last axis of size 1), so the batch makes the calls of
    one track. The course: its start ``c0`` and duration, the next course's start ``c1`` and
    duration, the end velocity and the flags. Past the course's end (``t < 0``) the schedule
    runs on at the end velocity.
    """
    schedule, rate, in_course, fraction = on_schedule(c0, span, v_end, t)
    has_next = next_span > 0.0
    zero = [0.0] * len(d)
    next_safe = where(has_next, next_span, 1.0)
    next_rate = _pick(has_next, [-x / next_safe for x in c1], zero)
    next_goal = _pick(has_next, [-(x + y) for x, y in zip(d, c1, strict=True)], zero)
    raw = [
        *map(operator.sub, d, schedule), *map(operator.sub, r, rate), *rate, *next_rate,
        *map(operator.neg, d), *next_goal,
    ]  # fmt: skip
    tail = [
        has * where(in_course, _clip(fraction, 0.0, 1.0), 0.0),
        has * _clip(t, TIME_LOW, TIME_HIGH),
        has * _clip(where(has_next, t + next_span, 0.0), TIME_LOW, TIME_HIGH),
        has,
        last,
    ]
    return raw, tail


def _squash(raw: np.ndarray, has: np.ndarray | None) -> np.ndarray:
    """``has * c tanh(x / c)`` of the scaled raw entries (..., 18), in place: the one
    transcendental, numpy's for one env and for many (its tanh may differ from libm's in the
    last bit). ``has`` None: every track is on (``1 * x`` is ``x``, bit for bit)."""
    raw /= _SCALES
    raw /= SQUASH
    np.tanh(raw, out=raw)
    raw *= SQUASH
    if has is not None:
        raw *= has
    return raw


_COURSE = struct.Struct(f"={_COURSE_SIZE}d")
_FLOAT64 = np.dtype(np.float64)
_ZEROS = (0.0, 0.0, 0.0)  # the next goal's entries when there is none


def _course_terms(course: list[float]) -> tuple[Any, ...]:
    """What :func:`_track` reads of a track's course entries alone (start, duration, next start
    and duration, end velocity, flags) and the next course's schedule velocity, by the same
    float operations: they hold from one goal switch to the next, so one env makes them once
    per course."""
    c0, span, c1, next_span, v_end = course[0:3], course[3], course[4:7], course[7], course[8:11]
    has_next = next_span > 0.0
    next_safe = next_span if has_next else 1.0
    next_rate = tuple(-x / next_safe for x in c1) if has_next else _ZEROS
    return (c0, span, v_end, next_rate, has_next, *c1, next_span, course[11], course[12])


def _reader(fields: list[tuple[int, int, bool]]) -> tuple[struct.Struct, list[int]]:
    """One struct that reads ``fields`` (first column, entries, whether as raw bytes) of a
    float64 record and skips the rest (one C call, no float made for an entry not read), and
    where each field starts in what it gives."""
    fmt, column, index = "=", 0, 0
    starts: dict[tuple[int, int, bool], int] = {}
    for field in sorted(fields):
        first, count, raw = field
        if first < column:
            raise ValueError("learner view: overlapping record fields")
        fmt += f"{8 * (first - column)}x" if first > column else ""
        fmt += f"{8 * count}s" if raw else f"{count}d"
        starts[field] = index
        index += 1 if raw else count
        column = first + count
    return struct.Struct(fmt), [starts[field] for field in fields]


class _OneEnv:
    """One env's view: :func:`_track`'s rule on floats with its per-course terms cached
    (numpy's per-call overhead dwarfs a few bodies' arithmetic; a float division costs more
    than an array's), then :func:`_squash`, the view's order and the cast on one work buffer.

    A track's cache is keyed by the bytes of its course entries (bit for bit: ``0.0 == -0.0``
    would not do), so a goal switch, a reset or a new scene refreshes it without being told.
    ``observe`` gives None for a record that is not contiguous float64 (the array path's).
    """

    def __init__(self, layout: ObservationLayout) -> None:
        n = layout.n_bodies
        tracks = [(d + o, r + o, t + o, c + o)
                  for o in range(0, n * BODY_BLOCK_SIZE, BODY_BLOCK_SIZE)
                  for d, r, t, c in _TRACK_COLUMNS]  # fmt: skip
        fields = [(n * BODY_BLOCK_SIZE, 1, False)]  # the time
        for d, r, t, c in tracks:
            fields += [(d, 3, False), (r, 3, False), (t, 1, False), (c, _COURSE_SIZE, True)]
        reader, starts = _reader(fields)
        self.read = reader.unpack_from
        self.time_at = starts[0]
        self.getters = [
            operator.itemgetter(d, d + 1, d + 2, r, r + 1, r + 2, t)
            for d, r, t in zip(starts[1::4], starts[2::4], starts[3::4], strict=True)
        ]
        self.courses = operator.itemgetter(*starts[4::4])
        self.keys: tuple[bytes, ...] = ()
        self.terms: list[tuple[Any, ...]] = []
        self.has: np.ndarray | None = None
        self.constants: np.ndarray | None = None
        self.hover: list[float] = []
        self.inverse_length = 0.0
        size = learner_size(n)
        squashed = len(tracks) * _RAW
        self.pack = struct.Struct(f"={size}d").pack_into
        self.values = np.zeros(size)  # raw entries, tails, hover actions, episode fraction
        self.raw = self.values[:squashed].reshape(len(tracks), _RAW)
        hover = squashed + 5 * len(tracks)
        order: list[int] = []
        for j in range(n):
            for k in (2 * j, 2 * j + 1):
                order += range(k * _RAW, (k + 1) * _RAW)
                order += range(squashed + 5 * k, squashed + 5 * k + 5)
            order += range(hover + 3 * j, hover + 3 * j + 3)
        order.append(size - 1)
        self.order = np.array(order)

    def _switch(self, keys: tuple[bytes, ...]) -> None:
        """New courses: their terms, and the flags :func:`_squash` multiplies by."""
        self.keys = keys
        self.terms = [_course_terms(list(_COURSE.unpack(key))) for key in keys]
        flags = [terms[-2] for terms in self.terms]
        self.has = None if flags.count(1.0) == len(flags) else np.array(flags)[:, None]

    def _bind_constants(self, constants: np.ndarray) -> None:
        """The hover actions clipped and the inverse length; a read-only array (what
        :meth:`LearnerView.constants` gives) is kept, so the next step checks its identity."""
        const = constants.tolist()
        self.hover = [_clip(h, -1.0, 1.0) for h in const[:-1]]
        self.inverse_length = const[-1]
        self.constants = None if constants.flags.writeable else constants

    def observe(self, record: np.ndarray, constants: np.ndarray) -> np.ndarray | None:
        dtype = record.dtype
        if dtype is not _FLOAT64 and dtype != _FLOAT64:  # (an unpickled one is a copy)
            return None
        try:
            fields = self.read(record)  # type: ignore[arg-type]  # an ndarray is a buffer
        except (ValueError, struct.error):  # not contiguous, or too short: the array path
            return None
        keys = self.courses(fields)
        if keys != self.keys:
            self._switch(keys)
        if constants is not self.constants:
            self._bind_constants(constants)
        lo, hi = TIME_LOW, TIME_HIGH
        raw: list[float] = []
        tails: list[float] = []
        for get, terms in zip(self.getters, self.terms, strict=True):
            dx, dy, dz, rx, ry, rz, t = get(fields)
            c0, span, v_end, next_rate, has_next, c1x, c1y, c1z, next_span, has, last = terms
            (sx, sy, sz), (vx, vy, vz), running, f = on_schedule(c0, span, v_end, t)
            nx, ny, nz = next_rate
            phase = has * ((0.0 if f <= 0.0 else 1.0 if f >= 1.0 else f) if running else 0.0)
            left = lo if t <= lo else hi if t >= hi else t
            if has_next:
                gx, gy, gz = -(dx + c1x), -(dy + c1y), -(dz + c1z)
                u = t + next_span
                ahead = lo if u <= lo else hi if u >= hi else u
            else:
                gx = gy = gz = ahead = 0.0
            raw += (
                dx - sx, dy - sy, dz - sz, rx - vx, ry - vy, rz - vz, vx, vy, vz, nx, ny, nz,
                -dx, -dy, -dz, gx, gy, gz,
            )  # fmt: skip
            tails += (phase, has * left, has * ahead, has, last)
        fraction = fields[self.time_at] * self.inverse_length
        raw += tails
        raw += self.hover
        raw.append(0.0 if fraction <= 0.0 else 1.0 if fraction >= 1.0 else fraction)
        self.pack(self.values, 0, *raw)  # type: ignore[arg-type]  # an ndarray is a buffer
        _squash(self.raw, self.has)
        return self.values.take(self.order).astype(np.float32)


def learner_observation(
    block: np.ndarray, hover: np.ndarray, episode_fraction: np.ndarray
) -> np.ndarray:
    """The learner's view (N, :func:`learner_size`) float32 of N sub-envs.

    ``block``: the planner's record (N, bodies, block) in float64; ``hover``: the hovering
    action of every body (N, bodies, 3); ``episode_fraction``: elapsed steps over the
    episode's steps (N,). The rule runs once on arrays over (N, bodies, 2 tracks).
    """
    if block.ndim != 3 or block.shape[-1] != BODY_BLOCK_SIZE:
        raise ValueError(f"learner_observation: expected (N, bodies, {BODY_BLOCK_SIZE}) record")
    n, b = block.shape[:2]
    g = block[..., _BATCH_COLUMNS]  # (N, bodies, 2, 20)
    has = g[..., 18:19]
    raw, tail = _track(
        [g[..., 0:3]], [g[..., 3:6]], g[..., 6:7], [g[..., 7:10]], g[..., 10:11],
        [g[..., 11:14]], g[..., 14:15], [g[..., 15:18]], has, g[..., 19:20],
    )  # fmt: skip
    squashed = _squash(np.concatenate(raw, axis=-1), has)
    tracks = np.concatenate((squashed, *tail), axis=-1).reshape(n, b, -1)
    bodies = np.concatenate((tracks, _clip(hover, -1.0, 1.0)), axis=-1).reshape(n, -1)
    fraction = _clip(episode_fraction, 0.0, 1.0).reshape(n, 1)
    return np.concatenate((bodies, fraction), axis=-1).astype(np.float32)


@observation_view
class LearnerView(ObservationView):
    """The learner's view (module docstring), ``observation="learner"``: every registered id's
    and the env's default."""

    name = "learner"

    def space(self) -> gym.spaces.Box:
        low, high = learner_bounds(self.layout.n_bodies)
        return gym.spaces.Box(low, high, dtype=np.float32)

    def constants(self, env: Any) -> np.ndarray:
        """The hovering action of every body (``-m g / force_limit``, 3 entries each) and
        ``1 / (max_steps dt)``, the inverse of the episode's length in seconds."""
        act = env._actuation
        gravity = np.asarray(act._gravity, dtype=np.float64)
        hover = [-m * gravity / f for m, f in zip(act._mass, act._flimit, strict=True)]
        constants = np.array([*np.concatenate(hover), 1.0 / (env.max_steps * env.dt)])
        constants.flags.writeable = False  # fixed: one env's view checks it by identity
        return constants

    _one: _OneEnv | None = None

    def bind(self, layout: ObservationLayout) -> ObservationView:
        view = super().bind(layout)
        view._one = None  # type: ignore[attr-defined]  # each env its own cache
        return view

    def observe(self, record: np.ndarray, constants: np.ndarray | None = None) -> np.ndarray:
        if record.ndim == 1 and constants is not None and constants.size:  # one env's step
            one = self._one
            if one is None:
                one = self._one = _OneEnv(self.layout)
            view = one.observe(record, constants)
            if view is not None:
                return view
        n_bodies = self.layout.n_bodies
        size = self.layout.size
        rows = record.reshape(-1, record.shape[-1])
        block = rows[:, : size - 1].reshape(len(rows), n_bodies, BODY_BLOCK_SIZE)
        if constants is None or constants.size == 0:
            constants = np.zeros(3 * n_bodies + 1)
        const = constants.reshape(-1, 3 * n_bodies + 1)
        hover = np.broadcast_to(const[:, :-1], (len(rows), 3 * n_bodies))
        fraction = rows[:, size - 1] * const[:, -1]
        view = learner_observation(block, hover.reshape(len(rows), n_bodies, 3), fraction)
        return view.reshape(*record.shape[:-1], -1)
