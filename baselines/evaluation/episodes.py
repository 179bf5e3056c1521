"""Seeded, scored episodes: one at a time on a single env, or many at once on the batched env.

Both runners return the same :class:`EpisodeRecord` for the same seed: the batched env steps
each sub-env bit for bit as ``gym.make(id)`` does (tests/sgc_env/envs/test_batch.py), so a policy
that acts on each observation row alone (the expert, the comparison controllers, SB3 models up to
the float rounding of a batched matrix product) gives the same episodes either way
(tests/baselines/evaluation/test_episodes.py). What the batched runner saves is the per-env Python
and PyBullet overhead: ``sgc evaluate --num-envs``.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import gymnasium as gym
import numpy as np

from baselines.policies import Policy
from sgc_env.envs.vector.vector_env import SGCVectorEnv
from sgc_env.metrics import GoalSpec, Tolerances, goals_from_scenario, score_episode

__all__ = ["EpisodeRecord", "run_episode", "run_episodes_batched", "sub_info"]


@dataclass
class EpisodeRecord:
    """One scored episode. ``infos`` (and ``initial_info``) are kept only when asked.

    ``wall_time_s``: the episode's own wall clock on a single env; on the batched env, its
    share (by steps) of the batch's wall clock, so that the shares add up to the whole run.
    """

    episode: int
    seed: int
    steps: int
    episode_return: float
    terminated: bool
    card: dict[str, Any]
    goals: list[list[GoalSpec]]
    dt: float
    wall_time_s: float
    infos: list[dict[str, Any]] | None = None
    initial_info: dict[str, Any] | None = None


def _record(
    env: Any,
    infos: list[dict[str, Any]],
    initial_info: dict[str, Any],
    tolerances: Tolerances | None,
    keep_infos: bool,
    **fields: Any,
) -> EpisodeRecord:
    """Score one finished episode of ``env`` (the unwrapped env that ran it)."""
    goals = goals_from_scenario(env.scenario)
    card = score_episode(infos, goals, env.dt, tolerances, initial_info=initial_info)
    return EpisodeRecord(
        card=card, goals=goals, dt=float(env.dt), steps=len(infos),
        infos=infos if keep_infos else None, initial_info=initial_info if keep_infos else None,
        **fields,
    )  # fmt: skip


def run_episode(
    policy: Policy,
    env: gym.Env,
    seed: int,
    *,
    episode: int = 0,
    tolerances: Tolerances | None = None,
    keep_infos: bool = False,
    max_steps: int = 100_000,
    frames: list[Any] | None = None,
    on_step: Callable[[gym.Env, int, Mapping[str, Any]], None] | None = None,
) -> EpisodeRecord:
    """Run and score one episode from ``env.reset(seed=seed)`` with a deterministic policy.

    ``frames``: a list to append ``env.render()`` to after the reset and every step (for
    videos; the env needs ``render_mode="rgb_array"``). ``on_step(env, step, info)`` is called
    after the reset (step 0) and after every step, for progress bars and custom rendering.
    """
    started = time.perf_counter()
    obs, initial_info = env.reset(seed=seed)
    if frames is not None:
        frames.append(env.render())
    if on_step is not None:
        on_step(env, 0, initial_info)
    infos: list[dict[str, Any]] = []
    state, total, terminated = None, 0.0, False
    first = True
    for _ in range(max_steps):
        action, state = policy.predict(
            obs, state=state, episode_start=np.array([first]), deterministic=True
        )
        first = False
        obs, reward, terminated, truncated, info = env.step(action)
        infos.append(info)
        total += float(reward)
        if frames is not None:
            frames.append(env.render())
        if on_step is not None:
            on_step(env, len(infos), info)
        if terminated or truncated:
            break
    return _record(
        env.unwrapped, infos, initial_info, tolerances, keep_infos,
        episode=episode, seed=seed, episode_return=total, terminated=bool(terminated),
        wall_time_s=time.perf_counter() - started,
    )  # fmt: skip


def sub_info(infos: Mapping[str, Any], i: int) -> dict[str, Any]:
    """Sub-env ``i``'s info from a vector env's dict of arrays with ``_key`` masks."""
    out = {}
    for key, value in infos.items():
        if key[0] != "_":
            mask = infos.get("_" + key)
            if mask is None or mask[i]:
                out[key] = value[i]
    return out


def _copy_row(into: Any, source: Any, i: int) -> None:
    """Row ``i`` of a batched observation (an array, or a dict of them) into ``into``."""
    if isinstance(into, dict):
        for key in into:
            into[key][i] = source[key][i]
    else:
        into[i] = source[i]


@dataclass
class _Running:
    """An episode in progress on one sub-env."""

    episode: int
    seed: int
    initial_info: dict[str, Any]
    infos: list[dict[str, Any]]
    total: float = 0.0


def run_episodes_batched(
    policy: Policy,
    env: SGCVectorEnv,
    seeds: Sequence[int],
    *,
    tolerances: Tolerances | None = None,
    keep_infos: int = 0,
    max_steps: int = 100_000,
) -> list[EpisodeRecord]:
    """Episode k from ``reset(seed=seeds[k])``, run on the sub-envs of ``env`` (an SGC batched
    env, :func:`sgc_env.envs.vector.vector_env.make_vec`) as they come free; records in episode
    order.

    Each sub-env resets by ``options["reset_mask"]`` with its next episode's seed once its
    episode ends (so no autoreset runs with an unwanted seed); a sub-env left without an
    episode keeps stepping with the policy's action and is ignored. ``keep_infos``: how many
    leading episodes keep their infos; ``max_steps`` cuts an episode as :func:`run_episode`
    does.
    """
    n, episodes = env.num_envs, len(seeds)
    if not 1 <= n <= episodes:
        raise ValueError(
            f"{episodes} episodes on {n} sub-envs: use at most one sub-env per episode"
        )
    started = time.perf_counter()
    running: list[_Running | None] = [None] * n
    records: dict[int, EpisodeRecord] = {}
    queue = list(range(n, episodes))
    obs, infos = env.reset(seed=[int(s) for s in seeds[:n]])
    for i in range(n):
        running[i] = _Running(i, int(seeds[i]), sub_info(infos, i), [])
    fresh = np.ones(n, dtype=bool)

    def start(ended: np.ndarray) -> np.ndarray:
        """Reset sub-envs whose episode ended onto the next episodes; their mask."""
        chosen = [int(i) for i in np.flatnonzero(ended)][: len(queue)]
        mask = np.zeros(n, dtype=bool)
        mask[chosen] = True
        if not chosen:
            return mask
        batch_seeds: list[int | None] = [None] * n
        for i in chosen:
            k = queue.pop(0)
            batch_seeds[i] = int(seeds[k])
            running[i] = _Running(k, int(seeds[k]), {}, [])
        obs_now, reset_infos = env.reset(seed=batch_seeds, options={"reset_mask": mask})
        for i in chosen:
            run = running[i]
            assert run is not None
            run.initial_info = sub_info(reset_infos, i)
            _copy_row(obs, obs_now, i)
        return mask

    state = None
    while any(r is not None for r in running):
        action, state = policy.predict(obs, state=state, episode_start=fresh, deterministic=True)
        obs, rewards, terminated, truncated, infos = env.step(action)
        ended = np.zeros(n, dtype=bool)
        for i, run in enumerate(running):
            if run is None:
                continue
            run.infos.append(sub_info(infos, i))
            run.total += float(rewards[i])
            if terminated[i] or truncated[i] or len(run.infos) >= max_steps:
                ended[i] = True
                records[run.episode] = _record(
                    env.envs[i], run.infos, run.initial_info, tolerances,
                    run.episode < keep_infos, episode=run.episode, seed=run.seed,
                    episode_return=run.total, terminated=bool(terminated[i]), wall_time_s=0.0,
                )  # fmt: skip
                running[i] = None
        fresh = start(ended) if ended.any() else np.zeros(n, dtype=bool)
    ordered = [records[k] for k in range(episodes)]
    total_steps = sum(r.steps for r in ordered)
    elapsed = time.perf_counter() - started
    for r in ordered:
        r.wall_time_s = elapsed * r.steps / total_steps if total_steps else 0.0
    return ordered
