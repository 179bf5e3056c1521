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
sub-env's :meth:`LearnerView.constants` (the hovering action, the episode's length), so the
single env (one row) and the batched env (N rows) share this one function.
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np

from sgc_env.observation import BODY_BLOCK_SIZE, ObservationLayout

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

_L = ObservationLayout(1)


def _cols(name: str) -> slice:
    return _L.body_slice(0, name)


def _gather(*fields: str) -> np.ndarray:
    """Block columns of ``fields`` (position track's then orientation track's), (2, columns)."""
    out = []
    for track, deviation, rate in (
        ("position", "position_deviation", "point_velocity"),
        ("orientation", "orientation_deviation", "angular_velocity"),
    ):
        names = [f.format(track=track, deviation=deviation, rate=rate) for f in fields]
        out.append(np.concatenate([np.r_[_cols(name)] for name in names]))
    return np.array(out)


# The columns both tracks read, gathered by one fancy index each (N, bodies, 2, width): the
# view costs numpy's per-call overhead, so the two tracks share every call.
_VECTORS = _gather(
    "{deviation}", "{rate}", "{track}_course_start", "{track}_next_start", "{track}_end_velocity"
)
_SCALARS = _gather("{track}_time_left", "{track}_course_duration", "{track}_next_duration")
_FLAGS = _gather("{track}_flags")
_SCALES = np.array([ERROR_SCALE] * 3 + [RATE_SCALE] * 3 + [VELOCITY_SCALE] * 6 + [GOAL_SCALE] * 6)


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


def _squash(x: np.ndarray) -> np.ndarray:
    return SQUASH * np.tanh(x / SQUASH)


def _clip(x: np.ndarray, low: float, high: float) -> np.ndarray:
    """``np.clip``'s values (NaN stays NaN) at a third of its call overhead on small arrays."""
    return np.minimum(np.maximum(x, low), high)


def _tracks(block: np.ndarray) -> np.ndarray:
    """The 23 entries of both tracks of every (row, body) of ``block`` (N, bodies, block):
    (N, bodies, 2, 23), position track first."""
    vectors = block[..., _VECTORS].reshape(*block.shape[:-1], 2, 5, 3)
    d, r, c0, c1, v_end = (vectors[..., k, :] for k in range(5))
    scalars = block[..., _SCALARS]
    t, span, next_span = scalars[..., 0], scalars[..., 1], scalars[..., 2]
    flag = block[..., _FLAGS]
    has = flag[..., 0:1]
    in_course = ((t >= 0.0) & (span > 0.0))[..., None]
    safe_span = np.where(span > 0.0, span, 1.0)[..., None]
    fraction = t[..., None] / safe_span
    schedule = np.where(in_course, c0 * fraction, -v_end * t[..., None])
    schedule_rate = np.where(in_course, -c0 / safe_span, v_end)
    has_next = (next_span > 0.0)[..., None]
    next_rate = np.where(has_next, -c1 / np.where(has_next, next_span[..., None], 1.0), 0.0)
    next_goal = np.where(has_next, -(d + c1), 0.0)
    next_time = np.where(has_next[..., 0], t + next_span, 0.0)
    raw = np.concatenate(
        (d - schedule, r - schedule_rate, schedule_rate, next_rate, -d, next_goal), axis=-1
    )
    times = np.stack((t, next_time), axis=-1)
    return np.concatenate(
        (
            has * _squash(raw / _SCALES),
            has * np.where(in_course, _clip(fraction, 0.0, 1.0), 0.0),
            has * _clip(times, TIME_LOW, TIME_HIGH),
            flag,
        ),
        axis=-1,
    )


def learner_observation(
    block: np.ndarray, hover: np.ndarray, episode_fraction: np.ndarray
) -> np.ndarray:
    """The learner's view (N, :func:`learner_size`) float32 of N sub-envs.

    ``block``: the planner's record (N, bodies, block) in float64; ``hover``: the hovering
    action of every body (N, bodies, 3); ``episode_fraction``: elapsed steps over the
    episode's steps (N,).
    """
    if block.ndim != 3 or block.shape[-1] != BODY_BLOCK_SIZE:
        raise ValueError(f"learner_observation: expected (N, bodies, {BODY_BLOCK_SIZE}) record")
    n, b = block.shape[:2]
    tracks = _tracks(block).reshape(n, b, 2 * LEARNER_TRACK_SIZE)
    bodies = np.concatenate((tracks, _clip(hover, -1.0, 1.0)), axis=-1).reshape(n, -1)
    fraction = _clip(episode_fraction, 0.0, 1.0).reshape(n, 1)
    return np.concatenate((bodies, fraction), axis=-1).astype(np.float32)


@observation_view
class LearnerView(ObservationView):
    """The learner's view (module docstring), ``observation="learner"``: the default of the
    ids' newest versions."""

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
        return np.array([*np.concatenate(hover), 1.0 / (env.max_steps * env.dt)])

    def observe(self, record: np.ndarray, constants: np.ndarray | None = None) -> np.ndarray:
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
