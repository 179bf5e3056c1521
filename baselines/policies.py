"""One way to name a policy: ``make_policy(spec, env)`` for the CLI and the evaluation harness.

Specs: ``expert`` (SGC with the scenario's end-velocity rule, by default the tangent rule),
``expert-paper`` (SGC with the paper's k rules, eqs. 12-14), ``expert-matched`` (SGC with
end velocities solved over whole tracks so accelerations match, :mod:`sgc_env.paper.matched`),
``expert-smooth`` (SGC sub-courses between transient sub-goals on the minimum-jerk reference,
:mod:`baselines.controllers.smooth_table`), ``dynamic-constraints``,
``minimum-jerk``, ``random``, ``shipped:<env id>`` (a model packaged with the project,
:mod:`baselines.common.shipped`), or the path of a Stable-Baselines3 model ``.zip`` (PPO, SAC,
TD3, A2C, DDPG; the algorithm is read from the saved data, SB3 and torch are imported only
then). Model files are loaded without unpickling anything (:mod:`baselines.models.model_files`)
unless the caller trusts them (``trust_model``, :func:`trusted_models`). A model trained
behind ``VecNormalize`` gets the statistics ``sgc train`` saved beside it
(:func:`vecnormalize_path`, :mod:`baselines.models.normalization`), so it sees the observations it
was trained on. The expert and the comparison controllers read the planner's view; built on an
env that observes another (the learner's view every id observes) they act on the env's planner view
of its current state themselves (:mod:`baselines.common.planner_view`). Every policy has the
SB3 signature
``predict(observation, state=None, episode_start=None, deterministic=True)``.
"""

from __future__ import annotations

import contextlib
import contextvars
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import Any, NamedTuple, Protocol, runtime_checkable

import gymnasium as gym
import numpy as np

from baselines.common.planner_view import planner_input, planner_reader
from baselines.common.shipped import resolve_policy_spec
from baselines.controllers.comparison_policies import (
    DynamicConstraintsController,
    MinimumJerkController,
    episode_model,
    observation_tick,
    predict_per_env,
    scenario_of,
)
from baselines.controllers.expert import SGCExpert
from baselines.models.model_files import algorithm_from_data, load_sb3_model
from baselines.models.normalization import load_statistics, statistics_path

__all__ = [
    "BUILTIN_POLICIES",
    "POLICY_FACTORIES",
    "BuiltinPolicy",
    "EpisodeExpert",
    "NormalizedPolicy",
    "Policy",
    "RandomPolicy",
    "algorithm_from_data",
    "load_sb3_model",
    "make_policy",
    "needs_planner_view",
    "policy_label",
    "policy_labels",
    "trusted_models",
    "vecnormalize_path",
]

_TRUST_MODELS: contextvars.ContextVar[bool] = contextvars.ContextVar("trust_models", default=False)


@runtime_checkable
class Policy(Protocol):
    """What the harness, the CLI and training callbacks drive: SB3's ``predict`` signature.

    The expert, the comparison controllers, :class:`RandomPolicy`, :class:`EpisodeExpert`,
    :class:`NormalizedPolicy` and SB3 models all satisfy it (``tests/baselines/test_policies.py``).
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
    when an episode starts (``episode_start`` or an observation at tick 0). On an env of
    another view it acts on the env's planner view of its current state, as the expert does.
    """

    def __init__(self, env: Any, end_rule: str | None = None) -> None:
        """``end_rule``: passed to each :class:`SGCExpert` (None: the scenario's rule)."""
        self.env = env
        self.end_rule = end_rule
        self._probe = episode_model(env, 0)
        self._experts: dict[int, SGCExpert] = {}
        self._planner = planner_reader(env, "EpisodeExpert")  # None: the planner's view

    def predict(
        self,
        observation: np.ndarray,
        state: Any = None,
        episode_start: Any = None,
        deterministic: bool = True,
    ) -> tuple[np.ndarray, Any]:
        observation = planner_input(self._planner, observation)

        def row_action(i: int, row: np.ndarray, start: bool) -> np.ndarray:
            if start or i not in self._experts or observation_tick(self._probe, row) == 0:
                model = episode_model(self.env, i)
                whole = self.end_rule in ("matched", "smooth")  # rules that read whole tracks
                scenario = scenario_of(self.env, i) if whole else None
                self._experts[i] = SGCExpert(model=model, end_rule=self.end_rule, scenario=scenario)
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
    """The ``VecNormalize`` statistics saved with a model (see
    :mod:`baselines.models.normalization`)."""
    return statistics_path(model_path)


@contextlib.contextmanager
def trusted_models(trust: bool = True) -> Iterator[None]:
    """Within the block, model files load with SB3's unpickling (``--trust-model``)."""
    token = _TRUST_MODELS.set(trust)
    try:
        yield
    finally:
        _TRUST_MODELS.reset(token)


def _with_saved_normalization(model: Any, path: str | Path, env: Any, trust: bool) -> Any:
    stats = statistics_path(path)
    if stats is None:
        return model
    return NormalizedPolicy(model, load_statistics(stats, env, trust_model=trust))


def needs_planner_view(spec: str) -> bool:
    """Whether the policy ``spec`` names reads the planner's view (the expert and the
    comparison controllers). On an env of another view such a policy reads the env's own
    planner view of its current state (:func:`~baselines.common.planner_view.planner_reader`);
    the harness makes its env with ``observation="planner"`` instead, the same scenes and
    dynamics on any version of an id, where the batched env's fast path need not hand out its
    sub-envs every step."""
    builtin = POLICY_FACTORIES.get(resolve_policy_spec(spec)) if isinstance(spec, str) else None
    return builtin is not None and builtin.flat


def _spaces_env(env: Any) -> Any:
    """The env whose spaces a policy acts in: ``env``, or a Gymnasium vector env's first
    sub-env (its ``action_space`` is the batch's; SB3 VecEnvs already give one env's)."""
    if not isinstance(env, gym.vector.VectorEnv):
        return env
    envs = getattr(env, "envs", None)
    if not envs:
        raise ValueError(
            f"policy: {type(env).__name__} keeps its sub-envs out of reach; use the SGC batched "
            "env (sgc_env.envs.vector.vector_env.make_vec) or SyncVectorEnv"
        )
    return envs[0]


def _one_torch_thread() -> None:
    """Run torch on one thread, as training does (``baselines.agents.train``): the policies
    are small MLPs, and a second thread only competes with the envs for the cores (measured:
    a batch of 4 observations took 20 ms with 2 threads on a busy 2-core machine, 1.9 ms with
    one)."""
    import torch

    torch.set_num_threads(1)


class BuiltinPolicy(NamedTuple):
    """How to make a built-in policy: ``make(env, seed)``; ``flat``: it reads the flat SGC
    observation, so the env is checked for one first."""

    make: Callable[[Any, int | None], Policy]
    flat: bool = True


def _expert(end_rule: str | None) -> BuiltinPolicy:
    return BuiltinPolicy(lambda env, seed: EpisodeExpert(env, end_rule=end_rule))


POLICY_FACTORIES: dict[str, BuiltinPolicy] = {
    "expert": _expert(None),
    "expert-paper": _expert("paper"),
    "expert-matched": _expert("matched"),
    "expert-smooth": _expert("smooth"),
    "dynamic-constraints": BuiltinPolicy(lambda env, seed: DynamicConstraintsController(env)),
    "minimum-jerk": BuiltinPolicy(lambda env, seed: MinimumJerkController(env)),
    "random": BuiltinPolicy(
        lambda env, seed: RandomPolicy(_spaces_env(env).action_space, seed), flat=False
    ),
}
"""The built-in policies by name: the one list of them."""

BUILTIN_POLICIES: tuple[str, ...] = tuple(POLICY_FACTORIES)


def make_policy(
    spec: str, env: Any, seed: int | None = None, trust_model: bool | None = None
) -> Policy:
    """A policy for ``env`` from its spec (see the module docstring); ``seed`` seeds ``random``.

    ``trust_model``: unpickle model files (None: as :func:`trusted_models` says, by default
    not; see :mod:`baselines.models.model_files`).
    """
    if not isinstance(spec, str) or not spec:
        raise ValueError(f"policy spec must be a non-empty string, got {spec!r}")
    spec = resolve_policy_spec(spec)
    builtin = POLICY_FACTORIES.get(spec)
    if builtin is not None:
        return builtin.make(env, seed)
    if spec.endswith(".zip") or Path(spec).suffix == ".zip" or Path(spec).exists():
        trust = _TRUST_MODELS.get() if trust_model is None else trust_model
        single = _spaces_env(env)
        _one_torch_thread()
        model = load_sb3_model(spec, env=single, trust_model=trust)
        return _with_saved_normalization(model, spec, single, trust)
    raise ValueError(
        f"policy: unknown spec {spec!r}; expected one of {list(BUILTIN_POLICIES)} or the path "
        "of a Stable-Baselines3 model .zip"
    )
