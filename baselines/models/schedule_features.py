"""Learner features: the error against the reward's schedule, computed inside the policy.

The raw observation carries everything a learner needs, but in a form that suits a planner:
D and D' of the goal point, the course start D_i(0), the time left and the float32 precision
residuals. The on-schedule reward (:mod:`sgc_env.envs.rewards`) pays for keeping
``D - D_sched`` small, with ``D_sched = D_i(0) t_left / T_i``; a learner that has to discover
this difference from raw metres and seconds through an MLP spends most of its budget there.
:class:`ScheduleFeatures` hands it over: per track (position, orientation) of every body,

| feature | size | scale |
|---|---|---|
| ``D - D_sched`` (on-schedule error) | 3 | / 0.05 m (rad) |
| ``D' - D'_sched`` (its rate; omega for phi) | 3 | / 0.5 m/s (rad/s) |
| ``D'_sched`` (the schedule's own velocity) | 3 | / 1 m/s (rad/s) |
| next course's schedule velocity | 3 | / 1 m/s (rad/s) |
| time fraction ``t_left / T_i`` in [0, 1], time left (s, clipped to [-1, 2]) | 2 | - |
| flags (has the track, current goal is the last) | 2 | - |

then the gravity term of each body (``m g / force_limit``, the action that hovers it, given at
construction). The precision residuals and absolute positions are dropped. ``squash=c`` maps
the error and its rate through ``c tanh(x / c)``: linear within a few units (the tolerances
are ~0.4 of a unit), bounded at ``c`` when a body is far off its schedule, so a ReLU or linear
policy is not handed inputs of 20-100 (a body metres off) that blow up its first updates
(`ppo-fast-linear` diverged, approx KL 12). Default ``None``: unchanged. Why a features
extractor rather than an observation wrapper: it is saved inside the SB3 ``.zip``, so a model
evaluates on the plain env id with nothing else to restore, and the expert's interface (the raw
observation) stays as it is. It needs the raw observation: combine it with
``VecNormalize(norm_obs=False)`` only.
"""

from __future__ import annotations

from collections.abc import Sequence

import gymnasium as gym
import torch as th
from stable_baselines3.common.torch_layers import BaseFeaturesExtractor

from sgc_env.observation import BODY_BLOCK_SIZE, GLOBAL_FIELDS, ObservationLayout

__all__ = ["TRACK_FEATURES", "ScheduleFeatures"]

TRACK_FEATURES = 16
_ERROR_SCALE = 0.05
_RATE_SCALE = 0.5
_TRACKS = (("position", "position_deviation", "point_velocity"),
           ("orientation", "orientation_deviation", "angular_velocity"))  # fmt: skip


def _index(layout: ObservationLayout, body: int, name: str) -> list[int]:
    s = layout.body_slice(body, name)
    return list(range(s.start, s.stop))


class ScheduleFeatures(BaseFeaturesExtractor):
    """On-schedule errors, schedule velocities, time fractions and gravity (table above)."""

    gravity: th.Tensor

    def __init__(
        self,
        observation_space: gym.spaces.Box,
        gravity: Sequence[float] | float = 0.0981,
        squash: float | None = None,
    ) -> None:
        if not isinstance(observation_space, gym.spaces.Box) or len(observation_space.shape) != 1:
            raise ValueError(f"ScheduleFeatures needs a flat Box, got {observation_space}")
        size = int(observation_space.shape[0])
        n_globals = sum(n for _, n in GLOBAL_FIELDS)
        n_bodies, rest = divmod(size - n_globals, BODY_BLOCK_SIZE)
        if n_bodies < 1 or rest:
            raise ValueError(
                f"ScheduleFeatures: an observation of {size} entries is not an SGC layout "
                f"(n * {BODY_BLOCK_SIZE} + {n_globals})"
            )
        if squash is not None and not (isinstance(squash, (int, float)) and squash > 0):
            raise ValueError(f"squash: expected a number > 0 or None, got {squash!r}")
        self.squash = None if squash is None else float(squash)
        if isinstance(gravity, (int, float)):
            gravity = [float(gravity)] * n_bodies
        weights = [float(g) for g in gravity]
        if len(weights) != n_bodies:
            raise ValueError(f"gravity: expected {n_bodies} values (one per body), got {weights}")
        super().__init__(observation_space, n_bodies * (2 * TRACK_FEATURES + 1))
        layout = ObservationLayout(n_bodies)
        fields = ("deviation", "rate", "time_left", "course_start", "course_duration",
                  "next_start", "next_duration", "end_velocity", "flags")  # fmt: skip
        for track, deviation, rate in _TRACKS:
            names = {key: f"{track}_{key}" for key in fields}
            names.update(deviation=deviation, rate=rate)
            for key in fields:
                rows = [_index(layout, b, names[key]) for b in range(n_bodies)]
                self.register_buffer(f"{track}_{key}", th.tensor(rows, dtype=th.long))
        self.register_buffer("gravity", th.tensor(weights, dtype=th.float32).unsqueeze(-1))

    def _track(self, obs: th.Tensor, track: str) -> th.Tensor:
        def get(key: str) -> th.Tensor:
            return obs[:, getattr(self, f"{track}_{key}")]  # (batch, bodies, size)

        deviation, rate, flags = get("deviation"), get("rate"), get("flags")
        time_left, raw_duration = get("time_left"), get("course_duration")
        duration = raw_duration.clamp(min=1e-6)
        in_course = (time_left >= 0) & (raw_duration > 0)
        start, end_velocity = get("course_start"), get("end_velocity")
        schedule = th.where(in_course, start * time_left / duration, -end_velocity * time_left)
        schedule_rate = th.where(in_course, -start / duration, end_velocity)
        next_duration = get("next_duration")
        next_rate = th.where(
            next_duration > 0, -get("next_start") / next_duration.clamp(min=1e-6),
            th.zeros_like(schedule_rate),
        )  # fmt: skip
        has_track = flags[..., :1]
        fraction = th.where(in_course, (time_left / duration).clamp(0.0, 1.0), 0.0)
        error = (deviation - schedule) / _ERROR_SCALE
        error_rate = (rate - schedule_rate) / _RATE_SCALE
        if self.squash is not None:
            error = self.squash * th.tanh(error / self.squash)
            error_rate = self.squash * th.tanh(error_rate / self.squash)
        return th.cat(
            [
                has_track * error,
                has_track * error_rate,
                has_track * schedule_rate,
                has_track * next_rate,
                has_track * fraction,
                has_track * time_left.clamp(-1.0, 2.0),
                flags,
            ],
            dim=-1,
        )

    def forward(self, observations: th.Tensor) -> th.Tensor:
        obs = observations.float()
        gravity = self.gravity.expand(obs.shape[0], -1, -1)
        tracks = [self._track(obs, "position"), self._track(obs, "orientation"), gravity]
        return th.cat(tracks, dim=-1).flatten(start_dim=1)
