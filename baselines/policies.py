"""One way to name a policy: ``make_policy(spec, env)`` for the CLI and the evaluation harness.

Specs: ``expert`` (SGC with the scenario's end-velocity rule, by default the tangent rule),
``expert-paper`` (SGC with the paper's k rules, eqs. 12-14), ``dynamic-constraints``,
``minimum-jerk``, ``random``, ``shipped:<env id>`` (a model packaged with the project,
:mod:`baselines.shipped`), or the path of a Stable-Baselines3 model ``.zip`` (PPO, SAC,
TD3, A2C, DDPG; the algorithm is read from the saved data, SB3 and torch are imported only
then). A model trained behind ``VecNormalize``
gets the statistics ``sgc train`` saved beside it (:func:`vecnormalize_path`), so it sees the
observations it was trained on. Every policy has the SB3 signature
``predict(observation, state=None, episode_start=None, deterministic=True)``.
"""

from __future__ import annotations

import importlib
import pickle
import re
from collections.abc import Sequence
from pathlib import Path
from typing import Any, Protocol, runtime_checkable

import gymnasium as gym
import numpy as np

from baselines.comparison_policies import (
    DynamicConstraintsController,
    MinimumJerkController,
    episode_model,
    observation_tick,
    predict_per_env,
)
from baselines.expert import SGCExpert
from baselines.shipped import resolve_policy_spec

__all__ = [
    "BUILTIN_POLICIES",
    "EpisodeExpert",
    "NormalizedPolicy",
    "Policy",
    "RandomPolicy",
    "algorithm_from_data",
    "load_sb3_model",
    "make_policy",
    "policy_label",
    "policy_labels",
    "vecnormalize_path",
]

BUILTIN_POLICIES: tuple[str, ...] = (
    "expert", "expert-paper", "dynamic-constraints", "minimum-jerk", "random"
)  # fmt: skip
SB3_ALGORITHMS: tuple[str, ...] = ("PPO", "SAC", "TD3", "A2C", "DDPG")


@runtime_checkable
class Policy(Protocol):
    """What the harness, the CLI and training callbacks drive: SB3's ``predict`` signature.

    The expert, the comparison controllers, :class:`RandomPolicy`, :class:`EpisodeExpert`,
    :class:`NormalizedPolicy` and SB3 models all satisfy it (``tests/test_policies.py``).
    SB3 models default to ``deterministic=False``; the harness always passes True.
    """

    def predict(
        self,
        observation: Any,
        state: Any = None,
        episode_start: np.ndarray | None = None,
        deterministic: bool = True,
    ) -> tuple[np.ndarray, Any]: ...


class RandomPolicy:
    """Uniform actions from a private, seeded copy of the action space (reproducible)."""

    def __init__(self, action_space: gym.spaces.Space, seed: int | None = None) -> None:
        if not isinstance(action_space, gym.spaces.Box):
            raise ValueError(f"action_space must be a Box, got {type(action_space).__name__}")
        self.action_space = gym.spaces.Box(
            action_space.low, action_space.high, action_space.shape, action_space.dtype, seed=seed
        )

    def predict(
        self,
        observation: Any,
        state: Any = None,
        episode_start: Any = None,
        deterministic: bool = True,
    ) -> tuple[np.ndarray, Any]:
        """A sample per observation (a batch gets one row each)."""
        obs = observation["observation"] if isinstance(observation, dict) else observation
        obs = np.asarray(obs)
        if obs.ndim >= 2:
            return np.stack([self.action_space.sample() for _ in range(obs.shape[0])]), state
        return self.action_space.sample(), state


class EpisodeExpert:
    """:class:`SGCExpert` with its env model re-read at every episode start, per sub-env.

    The expert reads masses, inertias and force limits once, at construction; a scenario
    swapped through ``reset(options={"scenario": ...})`` can change them, and a stale model
    under- or over-drives the body. This wrapper keeps one expert per sub-env and rebuilds it
    when an episode starts (``episode_start`` or an observation at tick 0).
    """

    def __init__(self, env: Any, end_rule: str | None = None) -> None:
        """``end_rule``: passed to each :class:`SGCExpert` (None: the scenario's rule)."""
        self.env = env
        self.end_rule = end_rule
        self._probe = episode_model(env, 0)
        self._experts: dict[int, SGCExpert] = {}

    def predict(
        self,
        observation: np.ndarray,
        state: Any = None,
        episode_start: Any = None,
        deterministic: bool = True,
    ) -> tuple[np.ndarray, Any]:
        def row_action(i: int, row: np.ndarray, start: bool) -> np.ndarray:
            if start or i not in self._experts or observation_tick(self._probe, row) == 0:
                model = episode_model(self.env, i)
                self._experts[i] = SGCExpert(model=model, end_rule=self.end_rule)
            return self._experts[i].action(row)

        return predict_per_env(observation, episode_start, row_action), state


class NormalizedPolicy:
    """``predict`` on raw observations for a model trained behind ``VecNormalize``."""

    def __init__(self, model: Any, vec_normalize: Any) -> None:
        self.model = model
        self.vec_normalize = vec_normalize

    def predict(
        self,
        observation: Any,
        state: Any = None,
        episode_start: Any = None,
        deterministic: bool = True,
    ) -> tuple[np.ndarray, Any]:
        obs = self.vec_normalize.normalize_obs(observation)
        return self.model.predict(obs, state, episode_start, deterministic)


def policy_label(spec: str) -> str:
    """Short name for output folders and tables: the spec, or a model file's stem."""
    return spec if spec in BUILTIN_POLICIES else Path(spec).stem


def policy_labels(specs: Sequence[str]) -> list[str]:
    """One distinct label per spec, for specs scored side by side.

    Model files sharing a stem (``a/final_model.zip``, ``b/final_model.zip``) are told apart
    by as many parent folders as it takes (``a-final_model``), so their outputs do not
    overwrite each other. A spec given twice (also as two spellings of one file) is an error.
    """
    files = [None if s in BUILTIN_POLICIES else Path(s).resolve() for s in specs]
    identities = [str(f) if f is not None else s for s, f in zip(specs, files, strict=True)]
    for spec, identity in zip(specs, identities, strict=True):
        if identities.count(identity) > 1:
            raise ValueError(f"policy: {spec!r} is given more than once")
    labels = [policy_label(s) for s in specs]
    folders = [() if f is None else f.parent.relative_to(f.anchor).parts for f in files]
    for depth in range(1, max(map(len, folders), default=0) + 1):
        clashing = {label for label in labels if labels.count(label) > 1}
        if not clashing:
            return labels
        labels = [
            "-".join([*parts[-depth:], f.stem]) if f is not None and label in clashing else label
            for f, parts, label in zip(files, folders, labels, strict=True)
        ]
    if len(set(labels)) < len(labels):
        raise ValueError(f"policy: cannot give {list(specs)} distinct labels; rename the files")
    return labels


def vecnormalize_path(model_path: str | Path) -> Path | None:
    """The ``VecNormalize`` statistics saved with a model by ``sgc train``, if there are any.

    ``<stem>.zip`` pairs with ``<stem>.vecnormalize.pkl`` beside it (shipped models) or else
    ``vecnormalize.pkl`` in the same folder (``final_model.zip``/``best_model.zip``); a
    checkpoint ``<prefix>_<N>_steps.zip`` with ``<prefix>_vecnormalize_<N>_steps.pkl``
    (SB3's ``CheckpointCallback`` names).
    """
    path = Path(model_path)
    checkpoint = re.fullmatch(r"(.*)_(\d+)_steps", path.stem)
    own = path.with_name(f"{path.stem}.vecnormalize.pkl")
    if own.is_file():
        return own
    if checkpoint:
        stats = path.with_name(f"{checkpoint[1]}_vecnormalize_{checkpoint[2]}_steps.pkl")
    else:
        stats = path.with_name("vecnormalize.pkl")
    return stats if stats.is_file() else None


def _with_saved_normalization(model: Any, path: str | Path) -> Any:
    stats = vecnormalize_path(path)
    if stats is None:
        return model
    with stats.open("rb") as fh:
        vec_normalize = pickle.load(fh)  # what VecNormalize.load does, without a venv
    vec_normalize.training = False
    return NormalizedPolicy(model, vec_normalize)


def algorithm_from_data(data: dict[str, Any]) -> str:
    """SB3 algorithm name of a saved model, from the data dict of its zip.

    The policy class's module tells SAC (``sac.policies``) and TD3/DDPG (``td3.policies``)
    apart from on-policy models (``common.policies``); DDPG is TD3 with ``policy_delay`` 1
    and no target noise clip, PPO has a ``clip_range`` that A2C lacks.
    """
    policy_class = data.get("policy_class")
    if policy_class is None:
        raise ValueError("model data has no policy_class: not a Stable-Baselines3 model")
    module = getattr(policy_class, "__module__", None)
    if module is None and isinstance(policy_class, dict):
        module = policy_class.get("__module__", "")
    module = str(module)
    if ".sac." in module:
        return "SAC"
    if ".td3." in module:
        ddpg = data.get("policy_delay") == 1 and data.get("target_noise_clip") == 0.0
        return "DDPG" if ddpg else "TD3"
    if ".ppo." in module or "clip_range" in data:
        return "PPO"
    if ".a2c." in module or ".common." in module:
        return "A2C"
    raise ValueError(f"cannot tell the algorithm of a model with policy class from {module!r}")


def load_sb3_model(path: str | Path, env: Any | None = None, device: str = "cpu") -> Any:
    """Load a Stable-Baselines3 model zip, detecting its algorithm.

    ``env`` is passed through to SB3: a HER model (a ``HerReplayBuffer`` in its data) cannot be
    loaded without the env that computes its rewards, and for the others SB3 checks that the
    model's spaces match the env's.
    """
    file = Path(path)
    if not file.is_file():
        raise ValueError(f"policy: model file {str(path)!r} does not exist")
    from stable_baselines3.common.save_util import load_from_zip_file

    data, _, _ = load_from_zip_file(file, load_data=True, device=device)
    if data is None:
        raise ValueError(f"policy: {str(path)!r} holds no model data")
    name = algorithm_from_data(data)
    algorithm = getattr(importlib.import_module("stable_baselines3"), name)
    return algorithm.load(file, env=env, device=device)


def _needs_flat_observation(env: Any, spec: str) -> None:
    if not isinstance(env.observation_space, gym.spaces.Box):
        raise ValueError(
            f"policy {spec!r} reads the flat SGC observation; this env's observation space is "
            f"{type(env.observation_space).__name__}"
        )


def make_policy(spec: str, env: Any, seed: int | None = None) -> Policy:
    """A policy for ``env`` from its spec (see the module docstring); ``seed`` seeds ``random``."""
    if not isinstance(spec, str) or not spec:
        raise ValueError(f"policy spec must be a non-empty string, got {spec!r}")
    spec = resolve_policy_spec(spec)
    if spec == "random":
        return RandomPolicy(env.action_space, seed)
    if spec in ("expert", "expert-paper", "dynamic-constraints", "minimum-jerk"):
        _needs_flat_observation(env, spec)
        if spec == "expert":
            return EpisodeExpert(env)
        if spec == "expert-paper":
            return EpisodeExpert(env, end_rule="paper")
        if spec == "dynamic-constraints":
            return DynamicConstraintsController(env)
        return MinimumJerkController(env)
    if spec.endswith(".zip") or Path(spec).suffix == ".zip" or Path(spec).exists():
        return _with_saved_normalization(load_sb3_model(spec, env=env), spec)
    raise ValueError(
        f"policy: unknown spec {spec!r}; expected one of {list(BUILTIN_POLICIES)} or the path "
        "of a Stable-Baselines3 model .zip"
    )
