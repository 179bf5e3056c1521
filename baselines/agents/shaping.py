"""Training-only reward shaping: the on-schedule cost without its flat top.

The env's ``schedule`` reward charges each track ``min(x, 1)``, ``x = |D - D_sched| / L``
(:mod:`sgc_env.envs.rewards`). The cap keeps a failure (charged 1 per track for every step it
leaves) never better than staying, but it is flat beyond ``x = 1``: a body more than a course
length off its schedule earns the same whether it drifts further or comes back. An untrained
rod leaves that band within about half a second (it falls), so for its first ~150k steps PPO
sees returns at the worst level with almost no slope to climb (docs/agents.md, "Rod from
scratch"). :class:`SmoothScheduleCost` replaces ``min(x, 1)`` by ``x / (1 + x)``: the same
slope at the schedule, still below 1 everywhere (so the failure charge stays the worst), and
strictly increasing, so "less far off" pays at every distance. It reads only the observation,
is applied to the training envs only (evaluation scores goals, not rewards) and sits below
``VecNormalize``.

``alive=True`` (``reward_shaping: smooth_alive``) also trades the failure charge (one lump of
the worst per-step reward times the steps left, up to ~-600 on the rod, at a random step) for
the same worst per-step reward paid as a bonus on every step the episode lives: undiscounted,
the return differs from the charged one by that bonus times the episode's length, a constant
of the scenario, so the ranking of policies is the same, but the value function no longer has
to predict when a lump lands. A terminated step's reward is recomputed without the charge (its
goal bonus, which a failing tick almost never has, is dropped with it).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from stable_baselines3.common.vec_env import VecEnv, VecEnvWrapper

from sgc_env.envs.rewards import EFFORT_WEIGHT, ORIENTATION_FLOOR, POSITION_FLOOR
from sgc_env.observation import BODY_BLOCK_SIZE, GLOBAL_FIELDS, ObservationLayout

__all__ = ["SmoothScheduleCost", "schedule_offsets"]

_TRACKS = (("position", "position_deviation", POSITION_FLOOR),
           ("orientation", "orientation_deviation", ORIENTATION_FLOOR))  # fmt: skip


def _n_bodies(size: int) -> int:
    n, rest = divmod(size - sum(n for _, n in GLOBAL_FIELDS), BODY_BLOCK_SIZE)
    if n < 1 or rest:
        raise ValueError(f"reward_shaping: an observation of {size} entries is not an SGC layout")
    return n


def schedule_offsets(obs: np.ndarray) -> np.ndarray:
    """``x = |D - D_sched| / L`` per (env, body, track) of a batch of observations; NaN where
    the body has no such track."""
    obs = np.asarray(obs, dtype=np.float64)
    n_bodies = _n_bodies(obs.shape[-1])
    layout = ObservationLayout(n_bodies)
    out = np.full((obs.shape[0], n_bodies, len(_TRACKS)), np.nan)
    for b in range(n_bodies):
        for k, (track, deviation, floor) in enumerate(_TRACKS):
            def get(name: str, b: int = b) -> np.ndarray:
                return obs[:, layout.body_slice(b, name)]

            d, left = get(deviation), get(f"{track}_time_left")
            start, duration = get(f"{track}_course_start"), get(f"{track}_course_duration")
            in_course = (left >= 0) & (duration > 0)
            schedule = np.where(in_course, start * left / np.where(duration > 0, duration, 1.0),
                                -get(f"{track}_end_velocity") * left)  # fmt: skip
            scale = np.maximum(np.linalg.norm(start, axis=1), floor)
            x = np.linalg.norm(d - schedule, axis=1) / scale
            out[:, b, k] = np.where(get(f"{track}_flags")[:, 0] > 0, x, np.nan)
    return out


class SmoothScheduleCost(VecEnvWrapper):
    """Adds ``mean_b sum_tracks (min(x, 1) - x / (1 + x))`` to the env's reward; with ``alive``
    the failure charge becomes a per-step bonus (see above)."""

    def __init__(self, venv: VecEnv, alive: bool = False) -> None:
        super().__init__(venv)
        _n_bodies(int(np.prod(venv.observation_space.shape or (0,))))
        self.alive = alive
        self._actions = np.zeros((venv.num_envs, *(venv.action_space.shape or ())))

    def reset(self) -> Any:
        return self.venv.reset()

    def step_async(self, actions: np.ndarray) -> None:
        self._actions = np.clip(np.asarray(actions, dtype=np.float64), -1.0, 1.0)
        self.venv.step_async(actions)

    def step_wait(self) -> Any:
        obs, rewards, dones, infos = self.venv.step_wait()
        after = np.array(obs, dtype=np.float64, copy=True)
        for i in np.flatnonzero(dones):  # the state the reward was computed on
            after[i] = infos[i]["terminal_observation"]
        x = schedule_offsets(after)
        capped = np.nan_to_num(np.minimum(x, 1.0)).sum(axis=2).mean(axis=1)
        smooth = np.nan_to_num(x / (1.0 + x)).sum(axis=2).mean(axis=1)
        shaped = rewards + capped - smooth
        if self.alive:
            effort = EFFORT_WEIGHT * np.mean(self._actions.reshape(len(dones), -1) ** 2, axis=1)
            for i in np.flatnonzero(dones):
                if not infos[i].get("TimeLimit.truncated", False):  # failed: drop the charge
                    shaped[i] = -smooth[i] - effort[i]
            worst = (~np.isnan(x)).sum(axis=2).mean(axis=1) + EFFORT_WEIGHT
            shaped = shaped + worst
        return obs, shaped.astype(rewards.dtype), dones, infos
