"""Expert demonstrations: seeded rollouts stored in one ``.npz`` file.

This flat npz is what behaviour cloning and DAgger read; a Minari dataset of the same
episodes is :mod:`baselines.agents.minari_data` (``sgc demos --format minari``). The format
(docs/agents.md):

| key | shape | meaning |
|---|---|---|
| observations | (N, obs_dim) float32 | observation the action was taken on |
| actions | (N, act_dim) float32 | the policy's action, in [-1, 1] |
| rewards | (N,) float32 | env reward of the step |
| terminations, truncations | (N,) bool | the step's ``terminated`` / ``truncated`` |
| episode_starts | (N,) bool | True on each episode's first step |
| seeds | (E,) int64 | reset seed of each episode |
| env_id | () str | registered id |
| env_kwargs | () str | JSON of the extra ``gym.make`` kwargs |
| pushes | () str | JSON of the push settings (:class:`~baselines.agents.pushes.Pushes`) |
| format_version | () int | 1 |

Files written before ``pushes`` existed load with the default (no pushes).
"""

from __future__ import annotations

import io
import json
import zipfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np

from baselines.agents.pushes import Pushes, apply_random_push, push_rng
from baselines.common.atomic_files import write_atomic
from sgc_env import check_env_id

__all__ = ["FORMAT_VERSION", "Demonstrations", "load_demos", "record_demos"]

FORMAT_VERSION = 1


@dataclass
class Demonstrations:
    """Flat step arrays of several episodes (see the module docstring for the fields)."""

    observations: np.ndarray
    actions: np.ndarray
    rewards: np.ndarray
    terminations: np.ndarray
    truncations: np.ndarray
    episode_starts: np.ndarray
    seeds: np.ndarray
    env_id: str
    env_kwargs: dict[str, Any] = field(default_factory=dict)
    pushes: Pushes = field(default_factory=Pushes)

    def __len__(self) -> int:
        return len(self.actions)

    @property
    def n_episodes(self) -> int:
        return int(self.episode_starts.sum())

    def save(self, path: str | Path) -> Path:
        """Write the npz at ``path`` atomically (an interrupted save leaves the old file)."""
        fh = io.BytesIO()
        np.savez_compressed(
            fh,
            observations=self.observations,
            actions=self.actions,
            rewards=self.rewards,
            terminations=self.terminations,
            truncations=self.truncations,
            episode_starts=self.episode_starts,
            seeds=self.seeds,
            env_id=np.array(self.env_id),
            env_kwargs=np.array(json.dumps(self.env_kwargs, sort_keys=True)),
            pushes=np.array(json.dumps(self.pushes.to_dict(), sort_keys=True)),
            format_version=np.array(FORMAT_VERSION),
        )
        return write_atomic(path, fh.getvalue())

    def extend(self, observations: np.ndarray, actions: np.ndarray) -> Demonstrations:
        """A copy with relabelled states appended (DAgger); step fields are zero-filled."""
        n = len(actions)
        return Demonstrations(
            observations=np.concatenate([self.observations, observations.astype(np.float32)]),
            actions=np.concatenate([self.actions, actions.astype(np.float32)]),
            rewards=np.concatenate([self.rewards, np.zeros(n, np.float32)]),
            terminations=np.concatenate([self.terminations, np.zeros(n, bool)]),
            truncations=np.concatenate([self.truncations, np.zeros(n, bool)]),
            episode_starts=np.concatenate([self.episode_starts, np.zeros(n, bool)]),
            seeds=self.seeds,
            env_id=self.env_id,
            env_kwargs=self.env_kwargs,
            pushes=self.pushes,
        )


def load_demos(path: str | Path) -> Demonstrations:
    """Read a file written by :meth:`Demonstrations.save` (never unpickling: a malformed or
    hostile file is a ValueError naming it)."""
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"demos: no such file {path}")
    try:
        return _read_demos(path)
    except (KeyError, ValueError, TypeError, OSError, EOFError, zipfile.BadZipFile) as exc:
        if str(exc).startswith("demos:"):
            raise
        raise ValueError(f"demos: {path} is not a demonstrations file from `sgc demos` "
                         f"({type(exc).__name__}: {exc})") from None  # fmt: skip


def _read_demos(path: Path) -> Demonstrations:
    with np.load(path, allow_pickle=False) as data:
        version = int(data["format_version"]) if "format_version" in data else None
        if version != FORMAT_VERSION:
            raise ValueError(
                f"demos: {path} has format_version {version}, expected {FORMAT_VERSION}"
            )
        return Demonstrations(
            observations=data["observations"],
            actions=data["actions"],
            rewards=data["rewards"],
            terminations=data["terminations"],
            truncations=data["truncations"],
            episode_starts=data["episode_starts"],
            seeds=data["seeds"],
            env_id=str(data["env_id"]),
            env_kwargs=json.loads(str(data["env_kwargs"])),
            pushes=Pushes(**json.loads(str(data["pushes"]))) if "pushes" in data else Pushes(),
        )


def record_demos(
    env_id: str,
    episodes: int,
    seed: int,
    env_kwargs: dict[str, Any] | None = None,
    policy: Any | None = None,
    pushes: Pushes | None = None,
) -> Demonstrations:
    """Roll out ``policy`` on seeds ``seed .. seed+episodes-1``.

    The default policy is the harness's ``expert`` (an :class:`SGCExpert` rebuilt at every
    episode start, because random scenarios redraw the force limits on reset). With
    ``pushes``, a pushed step records the observation after the push and the action taken on
    it, which for the expert is the recovery from the push.
    """

    check_env_id(env_id, "env")
    if episodes < 1:
        raise ValueError(f"episodes must be >= 1, got {episodes}")
    env_kwargs = dict(env_kwargs or {})
    pushes = pushes or Pushes()
    env = gym.make(env_id, **env_kwargs)
    try:
        if not isinstance(env.observation_space, gym.spaces.Box):
            raise ValueError(
                f"env: demos need a flat Box observation; {env_id} has {env.observation_space}"
            )
        if policy is None:
            from baselines.policies import make_policy

            policy = make_policy("expert", env)
        cols: dict[str, list] = {k: [] for k in ("obs", "act", "rew", "term", "trunc", "start")}
        seeds = np.arange(seed, seed + episodes, dtype=np.int64)
        for episode_seed in seeds:
            obs, _ = env.reset(seed=int(episode_seed))
            rng, tick = push_rng(int(episode_seed)), 0
            done, first = False, True
            while not done:
                obs = apply_random_push(env, obs, pushes, rng, tick)
                action, _ = policy.predict(obs, deterministic=True)
                action = np.clip(np.asarray(action, np.float32), -1.0, 1.0)
                next_obs, reward, terminated, truncated, _ = env.step(action)
                for key, value in zip(
                    cols, (obs, action, reward, terminated, truncated, first), strict=True
                ):
                    cols[key].append(value)
                obs, first, done = next_obs, False, terminated or truncated
                tick += 1
    finally:
        env.close()
    return Demonstrations(
        observations=np.asarray(cols["obs"], np.float32),
        actions=np.asarray(cols["act"], np.float32),
        rewards=np.asarray(cols["rew"], np.float32),
        terminations=np.asarray(cols["term"], bool),
        truncations=np.asarray(cols["trunc"], bool),
        episode_starts=np.asarray(cols["start"], bool),
        seeds=seeds,
        env_id=env_id,
        env_kwargs=env_kwargs,
        pushes=pushes,
    )
