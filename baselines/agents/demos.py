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
from baselines.common.bounded_npz import limit_rows, npz_shapes
from baselines.common.env_kwargs import check_env_kwargs
from sgc_env import check_env_id
from sgc_env.scenario.bounded import escaped, load_json

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


_STEP_ARRAYS = ("observations", "actions", "rewards", "terminations", "truncations",
                "episode_starts")  # fmt: skip


def load_demos(path: str | Path) -> Demonstrations:
    """Read a file written by :meth:`Demonstrations.save` (never unpickling; every array sized
    from its header before it is read: a malformed or hostile file is a ValueError naming it)."""
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"demos: no such file {escaped(path)}")
    where = f"demos: {escaped(path)}"
    shapes = npz_shapes(path, where)
    limit_rows(shapes, where)
    try:
        return _read_demos(path, where)
    except (KeyError, ValueError, TypeError, OSError, EOFError, zipfile.BadZipFile,
            MemoryError) as exc:  # fmt: skip
        if str(exc).startswith("demos:"):
            raise
        raise ValueError(f"{where} is not a demonstrations file from `sgc demos` "
                         f"({type(exc).__name__}: {escaped(exc)})") from None  # fmt: skip


def _read_demos(path: Path, where: str) -> Demonstrations:
    with np.load(path, allow_pickle=False) as data:
        version = int(data["format_version"]) if "format_version" in data else None
        if version != FORMAT_VERSION:
            raise ValueError(f"{where} has format_version {version}, expected {FORMAT_VERSION}")
        steps = {key: data[key] for key in _STEP_ARRAYS}
        env_id = check_env_id(str(data["env_id"]), f"{where}: env_id")
        env_kwargs = load_json(str(data["env_kwargs"]), f"{where}: env_kwargs")
        pushes = load_json(str(data["pushes"]), f"{where}: pushes") if "pushes" in data else {}
        seeds = data["seeds"]
    _check_steps(steps, where)
    if not isinstance(env_kwargs, dict) or not isinstance(pushes, dict):
        raise ValueError(f"{where}: env_kwargs and pushes must be JSON objects")
    env_kwargs = check_env_kwargs(env_id, env_kwargs, f"{where}: env_kwargs")
    return Demonstrations(**steps, seeds=seeds, env_id=env_id, env_kwargs=env_kwargs,
                          pushes=Pushes(**pushes))  # fmt: skip


def _check_steps(steps: dict[str, np.ndarray], where: str) -> None:
    """One row per step in every array, 2-D finite observations and actions in [-1, 1]."""
    rows = {key: value.shape[0] if value.ndim else -1 for key, value in steps.items()}
    if len(set(rows.values())) != 1:
        raise ValueError(f"{where}: the step arrays differ in length ({rows})")
    obs, actions = steps["observations"], steps["actions"]
    if obs.ndim != 2 or actions.ndim != 2 or obs.dtype.kind != "f" or actions.dtype.kind != "f":
        raise ValueError(f"{where}: observations and actions must be 2-D float arrays, got "
                         f"{obs.dtype}{obs.shape} and {actions.dtype}{actions.shape}")  # fmt: skip
    if not (np.all(np.isfinite(obs)) and np.all(np.abs(actions) <= 1.0)):
        raise ValueError(f"{where}: observations must be finite and actions in [-1, 1]")


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
    episode start, because random scenarios redraw the force limits on reset); on an env of the
    learner's view it acts on the env's planner view of the same state
    (:mod:`baselines.common.planner_view`), and the file stores the env's own observation. With
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
