"""Expert demonstrations as a Minari dataset (``sgc demos --format minari``; extra ``minari``).

Two choices keep the dataset exact and loadable without changing the env's contract:

- **Actions are stored as the float64 the expert gives the env.** The env's action space is a
  float32 Box, but the env uses whatever precision it is handed; rounding the expert's action
  to float32 moves a thin rod's orientation at a goal by up to ~1e-9 rad (see
  :meth:`~baselines.common.env_model.EnvModel.action_from_wrenches`). The dataset declares a float64
  Box with the env's bounds, so its actions belong to its space, and replaying them through
  ``dataset.recover_environment()`` reproduces the recorded observations bit for bit.
- **Infos have one fixed shape per step** (:func:`fixed_info`): the env reports
  ``goal_reached`` only on goal ticks, as a list of dicts, which a columnar store cannot hold.
  Here every step has ``goal_reached`` (per body, bool) and ``goal_position_error`` /
  ``goal_orientation_error`` (per body, NaN where no goal was reached), beside the env's other
  (fixed-shape) entries.

Episodes are assembled as Minari ``EpisodeBuffer``s and written with
``minari.create_dataset_from_buffers`` (HDF5), which needs only ``minari[hdf5]``; Minari's own
``DataCollector`` would add jax (``minari[create]``) for tree bookkeeping. The dataset is
written into a hidden staging folder beside Minari's datasets and renamed into place, so an
interrupted write leaves no half dataset under its id.
"""

from __future__ import annotations

import contextlib
import math
import os
import tempfile
from collections.abc import Iterator, Mapping
from pathlib import Path
from typing import Any

import gymnasium as gym
import minari
import numpy as np
from minari.data_collector import EpisodeBuffer
from minari.dataset.minari_dataset import DATASET_ID_RE
from minari.storage.datasets_root_dir import get_dataset_path

__all__ = ["check_dataset_id", "fixed_info", "float64_action_space", "record_minari"]

_GOAL_KEYS = ("position_error", "orientation_error")


def float64_action_space(space: gym.spaces.Box) -> gym.spaces.Box:
    """The env's action Box with float64 entries: the precision the expert acts in."""
    return gym.spaces.Box(
        space.low.astype(np.float64), space.high.astype(np.float64), space.shape, np.float64
    )


def fixed_info(info: Mapping[str, Any], n_bodies: int) -> dict[str, Any]:
    """The env's step info with ``goal_reached`` as fixed-shape per-body arrays."""
    out = {k: v for k, v in info.items() if k != "goal_reached"}
    reached = np.zeros(n_bodies, dtype=bool)
    errors = {key: np.full(n_bodies, np.nan) for key in _GOAL_KEYS}
    for event in info.get("goal_reached", ()):
        body = int(event["body"])
        reached[body] = True
        for key in _GOAL_KEYS:
            value = event.get(key)
            errors[key][body] = math.nan if value is None else float(value)
    out["goal_reached"] = reached
    for key in _GOAL_KEYS:
        out[f"goal_{key}"] = errors[key]
    return out


def _stack_infos(infos: list[dict[str, Any]]) -> dict[str, np.ndarray]:
    return {key: np.stack([np.asarray(i[key]) for i in infos]) for key in infos[0]}


@contextlib.contextmanager
def _datasets_root(path: str) -> Iterator[None]:
    """Minari reads its datasets folder from ``MINARI_DATASETS_PATH`` at every call."""
    saved = os.environ.get("MINARI_DATASETS_PATH")
    os.environ["MINARI_DATASETS_PATH"] = path
    try:
        yield
    finally:
        if saved is None:
            del os.environ["MINARI_DATASETS_PATH"]
        else:
            os.environ["MINARI_DATASETS_PATH"] = saved


def check_dataset_id(dataset_id: str) -> None:
    """Minari's id form with its version required: an unversioned id fails deep inside Minari,
    and the id names the folder written, so it is checked before any work."""
    match = DATASET_ID_RE.fullmatch(dataset_id)
    if match is None or match.group("version") is None:
        raise ValueError(
            f"dataset_id: expected (namespace/)name-v<version>, e.g. 'sgc/point/expert-v0'; "
            f"got {dataset_id!r}"
        )


def check_dataset_free(dataset_id: str) -> Path:
    """Where dataset ``dataset_id`` goes; a ``ValueError`` if a dataset is there already.
    Checked before the rollouts (so a taken id costs no work) and again at the rename."""
    target = get_dataset_path(dataset_id)
    if target.exists():
        raise ValueError(f"dataset_id: a dataset {dataset_id!r} already exists at {target}")
    return target


def _write_in_place(dataset_id: str, **create: Any) -> minari.MinariDataset:
    """``minari.create_dataset_from_buffers`` into a staging folder, renamed into place."""
    target = check_dataset_free(dataset_id)
    root = get_dataset_path()
    with tempfile.TemporaryDirectory(dir=root, prefix=".staging-") as staging:
        with _datasets_root(staging):
            minari.create_dataset_from_buffers(dataset_id=dataset_id, **create)
        target.parent.mkdir(parents=True, exist_ok=True)
        os.rename(Path(staging) / dataset_id, target)
    return minari.load_dataset(dataset_id)


def record_minari(
    env_id: str,
    episodes: int,
    seed: int,
    dataset_id: str,
    env_kwargs: dict[str, Any] | None = None,
    **publisher: str,
) -> minari.MinariDataset:
    """Roll out the expert on seeds ``seed .. seed+episodes-1`` into Minari ``dataset_id``.

    Written under Minari's datasets folder (``MINARI_DATASETS_PATH``, else
    ``~/.minari/datasets``); an existing dataset of that id is an error (a ``ValueError``).
    ``publisher``: Minari's ``author``, ``author_email``, ``code_permalink`` (Minari warns
    when they are missing).
    """
    from baselines.policies import make_policy
    from sgc_env import check_env_id

    check_env_id(env_id)
    check_dataset_id(dataset_id)
    check_dataset_free(dataset_id)
    if episodes < 1:
        raise ValueError(f"episodes must be >= 1, got {episodes}")
    env = gym.make(env_id, **(env_kwargs or {}))
    try:
        if not isinstance(env.observation_space, gym.spaces.Box):
            raise ValueError(
                f"env: demos need a flat Box observation; {env_id} has {env.observation_space}"
            )
        base: Any = env.unwrapped
        n_bodies = len(base.scenario.bodies)
        action_space = env.action_space
        assert isinstance(action_space, gym.spaces.Box)  # every SGC id acts with a Box
        policy = make_policy("expert", env)
        buffers = []
        for k in range(episodes):
            obs, info = env.reset(seed=seed + k)
            observations: list[np.ndarray] = [obs]
            actions: list[np.ndarray] = []
            infos = [fixed_info(info, n_bodies)]
            rewards: list[float] = []
            terminations: list[bool] = []
            truncations: list[bool] = []
            done = False
            while not done:
                action, _ = policy.predict(obs, deterministic=True)
                obs, reward, terminated, truncated, info = env.step(action)
                observations.append(obs)
                actions.append(np.asarray(action, np.float64))
                infos.append(fixed_info(info, n_bodies))
                rewards.append(float(reward))
                terminations.append(bool(terminated))
                truncations.append(bool(truncated))
                done = terminated or truncated
            buffers.append(
                EpisodeBuffer(
                    id=k, seed=seed + k, observations=np.stack(observations),
                    actions=np.stack(actions), rewards=rewards, terminations=terminations,
                    truncations=truncations, infos=_stack_infos(infos),
                )  # fmt: skip
            )
        return _write_in_place(
            dataset_id,
            buffer=buffers,
            env=env,
            eval_env=env.spec,
            action_space=float64_action_space(action_space),
            algorithm_name="SGCExpert (baselines.policies 'expert')",
            description=(
                f"{episodes} expert episodes of {env_id} from seed {seed}; actions are the "
                "float64 the env received; infos: baselines.agents.minari_data.fixed_info"
            ),
            data_format="hdf5",
            **publisher,
        )
    finally:
        env.close()
