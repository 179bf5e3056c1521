"""Hyperparameters in rl-zoo3's YAML format: one file per algorithm, keyed by env id.

Kept in YAML (not code) so that a run is reproduced from the file plus the command line, and
so that rl-zoo3 users can read them. String-valued entries such as
``policy_kwargs: "dict(net_arch=[64, 64], activation_fn=nn.Tanh)"`` are parsed by a small
whitelisting AST walker, never by ``eval``.
"""

from __future__ import annotations

import ast
import inspect
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from baselines.common.network_caps import check_policy_kwargs
from baselines.common.shipped import hyperparams_file
from baselines.common.value_types import describe, matches
from baselines.models.features import ACTIVATIONS
from sgc_env.scenario.bounded import check_count, escaped, load_yaml, read_text

__all__ = [
    "ALGORITHMS",
    "Hyperparams",
    "algorithm_class",
    "linear_schedule",
    "load_hyperparams",
    "training_class",
    "parse_kwargs_string",
]

_NAME_PREFIXES = ("nn.", "th.nn.", "torch.nn.")
_STRING_KWARGS = ("policy_kwargs", "replay_buffer_kwargs")
_ZOO_KEYS = {"n_timesteps", "policy", "n_envs", "normalize", "noise_type", "noise_std"}


@dataclass
class Hyperparams:
    """One resolved entry: the zoo's own keys plus the keyword arguments for the SB3 class."""

    env_id: str
    algo: str
    n_timesteps: int
    policy: str | type  # an SB3 alias, or a class of this project (_policy_class)
    n_envs: int = 1
    normalize: bool = False
    normalize_kwargs: dict[str, Any] = field(default_factory=dict)
    noise_type: str | None = None
    noise_std: float = 0.1
    algo_kwargs: dict[str, Any] = field(default_factory=dict)
    raw: dict[str, Any] = field(default_factory=dict)


def _resolve_name(dotted: str, field_name: str) -> Any:
    import torch.nn as nn

    short = dotted
    for prefix in _NAME_PREFIXES:
        if dotted.startswith(prefix):
            short = dotted[len(prefix) :]
            break
    if short in ACTIVATIONS:
        return getattr(nn, short)
    if short == "StandardizeObservation":
        from baselines.models.features import StandardizeObservation

        return StandardizeObservation
    if short == "LearnerViewBodies":
        from baselines.models.per_body import LearnerViewBodies

        return LearnerViewBodies
    if short == "HerReplayBuffer":
        from stable_baselines3 import HerReplayBuffer

        return HerReplayBuffer
    raise ValueError(f"{field_name}: name {escaped(repr(dotted))} is not allowed (activations: "
                     f"{ACTIVATIONS})")  # fmt: skip


def _policy_class(name: str) -> str | type:
    """SB3's policy aliases stay strings; ``PerBodyPolicy`` is this project's class."""
    if name == "PerBodyPolicy":
        from baselines.models.per_body import PerBodyPolicy

        return PerBodyPolicy
    return name


def _dotted(node: ast.AST) -> str | None:
    if isinstance(node, ast.Name):
        return node.id
    if isinstance(node, ast.Attribute):
        base = _dotted(node.value)
        return None if base is None else f"{base}.{node.attr}"
    return None


def _literal(node: ast.AST, field_name: str) -> Any:
    if isinstance(node, ast.Constant):
        return node.value
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub):
        value = _literal(node.operand, field_name)
        if isinstance(value, (int, float)):
            return -value
    if isinstance(node, (ast.List, ast.Tuple)):
        items = [_literal(e, field_name) for e in node.elts]
        return items if isinstance(node, ast.List) else tuple(items)
    if isinstance(node, ast.Dict):
        return {
            _literal(k, field_name): _literal(v, field_name)
            for k, v in zip(node.keys, node.values, strict=True)
            if k is not None
        }
    if isinstance(node, ast.Call) and _dotted(node.func) == "dict" and not node.args:
        return {kw.arg: _literal(kw.value, field_name) for kw in node.keywords if kw.arg}
    name = _dotted(node)
    if name is not None:
        return _resolve_name(name, field_name)
    raise ValueError(f"{field_name}: unsupported expression {escaped(repr(ast.unparse(node)))}")


def parse_kwargs_string(text: str, field_name: str = "policy_kwargs") -> dict[str, Any]:
    """Parse ``"dict(net_arch=[64, 64], activation_fn=nn.Tanh)"`` without ``eval`` (deep or
    huge text is a ValueError too, never a RecursionError or MemoryError)."""
    try:
        tree = ast.parse(text.strip(), mode="eval")
        value = _literal(tree.body, field_name)
    except SyntaxError as exc:
        raise ValueError(f"{field_name}: cannot parse {escaped(repr(text))}: {exc.msg}") from None
    except (RecursionError, MemoryError):
        raise ValueError(f"{field_name}: nested too deeply to read") from None
    if not isinstance(value, dict):
        raise ValueError(f"{field_name}: expected dict(...) or {{...}}, got {escaped(repr(text))}")
    return value


def linear_schedule(initial: float):
    """rl-zoo3's ``lin_<value>``: decays linearly from ``initial`` to 0 over training."""

    def schedule(progress_remaining: float) -> float:
        return progress_remaining * initial

    return schedule


def _learning_rate(value: Any) -> Any:
    try:
        if isinstance(value, str) and value.startswith("lin_"):
            rate = float(value[4:])
            if math.isfinite(rate) and rate > 0:
                return linear_schedule(rate)
        elif isinstance(value, (str, int, float)) and not isinstance(value, bool):
            rate = float(value)
            if math.isfinite(rate) and rate > 0:
                return rate
    except (ValueError, OverflowError):
        pass
    raise ValueError(f"learning_rate: expected a finite number > 0 or lin_<number>, got "
                     f"{escaped(repr(value))}")  # fmt: skip


_NORMALIZE_KEYS = ("norm_obs", "norm_reward", "clip_obs", "clip_reward", "gamma", "epsilon")


def _normalize(value: Any, where: str) -> tuple[bool, dict[str, Any]]:
    """rl-zoo3's ``normalize``: a bool, or VecNormalize kwargs as a mapping or a dict string."""
    if isinstance(value, bool):
        return value, {}
    if isinstance(value, str):
        value = parse_kwargs_string(value, "normalize")
    if not isinstance(value, dict):
        raise ValueError(f"{where}: normalize must be true/false or a mapping, got {value!r}")
    unknown = sorted(set(value) - set(_NORMALIZE_KEYS))
    if unknown:
        raise ValueError(f"{where}: normalize: unknown keys {unknown} (known: {_NORMALIZE_KEYS})")
    for key, item in value.items():
        kind = bool if key.startswith("norm_") else float
        if not matches(item, kind):
            raise ValueError(f"{where}: normalize: {key} must be {describe(kind)}, got {item!r}")
        if kind is float and not (0.0 < item <= (1.0 if key == "gamma" else math.inf)):
            limit = "in (0, 1]" if key == "gamma" else "> 0"
            raise ValueError(f"{where}: normalize: {key} must be {limit}, got {item!r}")
    return True, dict(value)


ALGORITHMS: tuple[str, ...] = ("ppo", "sac", "td3", "her")


def algorithm_class(algo: str):
    """SB3 class for ``algo`` (HER is SAC with a ``HerReplayBuffer``)."""
    from stable_baselines3 import PPO, SAC, TD3

    classes = {"ppo": PPO, "sac": SAC, "td3": TD3, "her": SAC}
    if algo not in classes:
        raise ValueError(f"algo: unknown algorithm {algo!r}; choose from {ALGORITHMS}")
    return classes[algo]


SMOOTHNESS_KEYS = ("temporal", "spatial", "spatial_std")
"""PPO fields that train with :class:`baselines.agents.smooth_ppo.SmoothPPO` (CAPS terms)."""


def training_class(hp: Hyperparams) -> type:
    """The class that trains ``hp``: :func:`algorithm_class`, or ``SmoothPPO`` for a PPO entry
    that sets CAPS smoothness fields (a model it saves loads as a plain PPO)."""
    if hp.algo == "ppo" and any(key in hp.algo_kwargs for key in SMOOTHNESS_KEYS):
        from baselines.agents.smooth_ppo import SmoothPPO

        return SmoothPPO
    return algorithm_class(hp.algo)


def load_hyperparams(algo: str, env_id: str, directory: str | Path | None = None) -> Hyperparams:
    """Read ``<directory>/<algo>.yml`` (default: the packaged file) and resolve ``env_id``."""
    algo_cls = algorithm_class(algo)
    path = Path(directory) / f"{algo}.yml" if directory else hyperparams_file(algo)
    if not path.is_file():
        raise ValueError(f"algo: no hyperparameter file {escaped(path)}")
    text = read_text(path, "hyperparameters") if isinstance(path, Path) else path.read_text()
    table = load_yaml(text, f"hyperparameters {escaped(path)}")
    if not isinstance(table, dict):
        raise ValueError(f"{path}: expected a mapping of env id -> hyperparameters")
    if env_id not in table:
        raise ValueError(f"env: {path} has no hyperparameters for {env_id!r} (has "
                         f"{escaped(sorted(map(str, table)))})")  # fmt: skip
    entry = table[env_id]
    if not isinstance(entry, dict):
        raise ValueError(f"{path}: entry {env_id!r} must be a mapping")
    for key in ("n_timesteps", "policy"):
        if key not in entry:
            raise ValueError(f"{path}: {env_id}: missing field {key!r}")
    kwargs: dict[str, Any] = {}
    parameters = dict(inspect.signature(algo_cls.__init__).parameters)
    if algo == "ppo":  # the CAPS fields train with SmoothPPO (training_class)
        from baselines.agents.smooth_ppo import SmoothPPO

        smooth = inspect.signature(SmoothPPO.__init__, eval_str=True).parameters
        parameters.update({key: smooth[key] for key in SMOOTHNESS_KEYS})
    allowed = set(parameters) - {"self", "policy", "env"}
    for key, value in entry.items():
        if key in _ZOO_KEYS:
            continue
        if key not in allowed:
            raise ValueError(f"{path}: {env_id}: unknown field {key!r} for {algo_cls.__name__}")
        if key in _STRING_KWARGS and isinstance(value, str):
            try:
                value = parse_kwargs_string(value, key)
            except ValueError as exc:
                raise ValueError(f"{path}: {env_id}: {exc}") from None
        if key == "policy_kwargs":
            check_policy_kwargs(value, f"{path}: {env_id}: policy_kwargs")
        elif key == "learning_rate":
            try:
                value = _learning_rate(value)
            except ValueError as exc:
                raise ValueError(f"{path}: {env_id}: {exc}") from None
        elif key == "replay_buffer_class" and isinstance(value, str):
            try:
                value = _resolve_name(value, key)
            except ValueError as exc:
                raise ValueError(f"{path}: {env_id}: {exc}") from None
        if matches(value, parameters[key].annotation) is False:
            hint = describe(parameters[key].annotation)
            raise ValueError(f"{path}: {env_id}: {key} must be {hint}, got {value!r}")
        kwargs[key] = value
    try:
        normalize, normalize_kwargs = _normalize(entry.get("normalize", False), f"{path}: {env_id}")
    except ValueError as exc:
        message = str(exc)
        raise ValueError(message if message.startswith(str(path)) else f"{path}: {env_id}: "
                         f"{message}") from None  # fmt: skip
    noise_type = entry.get("noise_type")
    if noise_type not in (None, "normal"):
        raise ValueError(f"{path}: {env_id}: noise_type must be 'normal', got {noise_type!r}")
    try:
        n_timesteps = int(float(entry["n_timesteps"]))
        n_envs = int(entry.get("n_envs", 1))
        noise_std = float(entry.get("noise_std", 0.1))
    except (TypeError, ValueError, OverflowError):
        raise ValueError(f"{path}: {env_id}: n_timesteps, n_envs and noise_std must be finite "
                         "numbers") from None  # fmt: skip
    if not isinstance(entry["policy"], str):
        raise ValueError(f"{path}: {env_id}: policy must be a name such as MlpPolicy")
    if n_envs < 1:
        raise ValueError(f"{path}: {env_id}: n_envs must be >= 1, got {n_envs}")
    check_count(n_envs, "n_envs", f"{path}: {env_id}: n_envs")
    return Hyperparams(
        env_id=env_id,
        algo=algo,
        n_timesteps=n_timesteps,
        policy=_policy_class(entry["policy"]),
        n_envs=n_envs,
        normalize=normalize,
        normalize_kwargs=normalize_kwargs,
        noise_type=noise_type,
        noise_std=noise_std,
        algo_kwargs=kwargs,
        raw=dict(entry),
    )
