"""``VecNormalize`` statistics in plain JSON, so that no model's companion file is a pickle.

SB3's ``VecNormalize.save`` pickles the whole wrapper, and loading a pickle runs whatever
code the file holds. A model trained behind ``VecNormalize`` keeps here only what
normalising an observation needs (running means, variances, counts and the settings) in a
JSON file: Python writes floats that read back bit for bit, so a model scores exactly as it
did in its run. Old ``.pkl`` statistics are refused unless the caller trusts the file
(:func:`load_statistics` with ``trust_model=True``); :func:`convert_pickle` rewrites one
trusted pickle as JSON once.

Where the statistics of a model are (:func:`statistics_path`): ``<stem>.zip`` pairs with
``<stem>.vecnormalize.json`` beside it (shipped models), else ``vecnormalize.json`` in the
same folder (``final_model.zip``/``best_model.zip``), else ``<stem>/vecnormalize.json`` (where
rl-zoo3's trainer saves a run's statistics, as a pickle to convert once); a checkpoint
``<prefix>_<N>_steps.zip`` with ``<prefix>_vecnormalize_<N>_steps.json`` (SB3's
``CheckpointCallback`` names). The ``.pkl`` of the same name is found too, to be refused.
"""

from __future__ import annotations

import json
import math
import pickle
import re
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np

from baselines.common.atomic_files import write_atomic
from sgc_env.scenario.bounded import escaped, load_json, read_bounded

__all__ = [
    "FORMAT",
    "convert_pickle",
    "load_statistics",
    "save_statistics",
    "statistics_path",
]

FORMAT = "sgc-vecnormalize-1"
_SETTINGS = ("norm_obs", "norm_reward", "clip_obs", "clip_reward", "gamma", "epsilon")


def _candidates(model_path: str | Path) -> list[Path]:
    """Where a model's statistics may be, without suffix, best first."""
    path = Path(model_path)
    checkpoint = re.fullmatch(r"(.*)_(\d+)_steps", path.stem)
    own = path.with_name(f"{path.stem}.vecnormalize")
    if checkpoint:
        return [own, path.with_name(f"{checkpoint[1]}_vecnormalize_{checkpoint[2]}_steps")]
    # rl-zoo3 writes <env id>.zip and <env id>/vecnormalize.pkl in the run folder
    return [own, path.with_name("vecnormalize"), path.parent / path.stem / "vecnormalize"]


def statistics_path(model_path: str | Path) -> Path | None:
    """The ``VecNormalize`` statistics saved with a model (JSON, else a legacy pickle)."""
    for stem in _candidates(model_path):
        for suffix in (".json", ".pkl"):
            candidate = stem.with_name(stem.name + suffix)
            if candidate.is_file():
                return candidate
    return None


def _rms_dict(rms: Any) -> dict[str, Any]:
    mean = np.asarray(rms.mean, np.float64)
    var = np.asarray(rms.var, np.float64)
    return {"shape": list(mean.shape), "mean": mean.ravel().tolist(),
            "var": var.ravel().tolist(), "count": float(rms.count)}  # fmt: skip


def _state(vec_normalize: Any) -> dict[str, Any]:
    """The JSON-ready statistics of a ``VecNormalize`` (live or unpickled)."""
    state: dict[str, Any] = {"format": FORMAT}
    state.update({k: getattr(vec_normalize, k) for k in _SETTINGS})
    state["norm_obs_keys"] = getattr(vec_normalize, "norm_obs_keys", None)
    obs_rms = getattr(vec_normalize, "obs_rms", None) if vec_normalize.norm_obs else None
    if isinstance(obs_rms, dict):
        state["obs_rms"] = {key: _rms_dict(rms) for key, rms in obs_rms.items()}
    else:
        state["obs_rms"] = None if obs_rms is None else _rms_dict(obs_rms)
    state["ret_rms"] = _rms_dict(vec_normalize.ret_rms)
    return state


def save_statistics(vec_normalize: Any, path: str | Path) -> Path:
    """Write ``vec_normalize``'s statistics and settings to ``path`` (JSON, atomically)."""
    return write_atomic(path, json.dumps(_state(vec_normalize), indent=1, allow_nan=False) + "\n")


def _number(value: Any, where: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise ValueError(f"{where} must be a finite number, got {escaped(repr(value))}")
    return float(value)


def _rms(entry: Any, where: str, shape: tuple[int, ...]) -> Any:
    from stable_baselines3.common.running_mean_std import RunningMeanStd

    if not isinstance(entry, dict) or not {"shape", "mean", "var", "count"} <= set(entry):
        raise ValueError(f"{where}: expected shape, mean, var and count")
    if not isinstance(entry["shape"], list) or entry["shape"] != list(shape):
        raise ValueError(f"{where}: statistics of shape {escaped(entry['shape'])} do not fit the "
                         f"env's observations of shape {shape}")  # fmt: skip
    rms = RunningMeanStd(shape=shape)
    try:
        rms.mean = np.asarray(entry["mean"], np.float64).reshape(shape)
        rms.var = np.asarray(entry["var"], np.float64).reshape(shape)
    except (TypeError, ValueError, OverflowError) as exc:
        raise ValueError(f"{where}: mean and var must be {shape} numbers ({escaped(exc)})"
                         ) from None  # fmt: skip
    if not (np.all(np.isfinite(rms.mean)) and np.all(np.isfinite(rms.var))
            and np.all(rms.var >= 0)):  # fmt: skip
        raise ValueError(f"{where}: mean and var must be finite and var >= 0 (an infinite "
                         "variance scales every observation to 0)")  # fmt: skip
    rms.count = _number(entry["count"], f"{where}.count")
    if rms.count < 0:
        raise ValueError(f"{where}.count must be >= 0, got {rms.count}")
    return rms


#: Setting -> (low, high) it must lie in: clipping at 0 or below zeroes every observation.
_RANGES = {"clip_obs": (1e-6, math.inf), "clip_reward": (1e-6, math.inf), "gamma": (0.0, 1.0),
           "epsilon": (0.0, 1.0)}  # fmt: skip


def _setting(state: dict[str, Any], key: str, where: str) -> Any:
    if key.startswith("norm"):
        if not isinstance(state[key], bool):
            raise ValueError(f"{where}.{key} must be true or false, got {escaped(state[key])}")
        return state[key]
    value = _number(state[key], f"{where}.{key}")
    low, high = _RANGES[key]
    if not low <= value <= high:
        raise ValueError(f"{where}.{key} must be in [{low:g}, {high:g}], got {value:g}")
    return value


def _from_state(state: Any, env: Any, where: str) -> Any:
    """A ``VecNormalize`` without a venv (``normalize_obs`` only) from checked statistics."""
    from stable_baselines3.common.vec_env import VecNormalize

    if not isinstance(state, dict) or state.get("format") != FORMAT:
        raise ValueError(f"{where}: not VecNormalize statistics (format {FORMAT!r} expected)")
    missing = sorted(set(_SETTINGS) - set(state))
    if missing:
        raise ValueError(f"{where}: missing {missing}")
    space = env.observation_space
    obs_rms: Any = None
    if state["norm_obs"]:
        if isinstance(space, gym.spaces.Dict):
            keys = state.get("norm_obs_keys") or list(space.spaces)
            entries = state.get("obs_rms")
            if (not isinstance(keys, list) or not all(isinstance(k, str) for k in keys)
                    or not isinstance(entries, dict)
                    or not set(keys) <= set(entries) & set(space.spaces)):  # fmt: skip
                raise ValueError(f"{where}: obs_rms keys do not fit the env's {list(space.spaces)}")
            obs_rms = {k: _rms(entries[k], f"{where}: obs_rms[{k!r}]", tuple(space[k].shape or ()))
                       for k in keys}  # fmt: skip
        else:
            obs_rms = _rms(state.get("obs_rms"), f"{where}: obs_rms", tuple(space.shape or ()))
    vec_normalize = VecNormalize.__new__(VecNormalize)
    settings = {k: _setting(state, k, where) for k in _SETTINGS}
    vec_normalize.__setstate__({
        **settings, "norm_obs_keys": state.get("norm_obs_keys"), "obs_rms": obs_rms,
        "ret_rms": _rms(state.get("ret_rms"), f"{where}: ret_rms", ()), "training": False,
        "observation_space": space, "action_space": env.action_space,
    })  # fmt: skip
    if obs_rms is None:
        del vec_normalize.obs_rms
    return vec_normalize


def _refuse_pickle(path: Path) -> ValueError:
    return ValueError(
        f"VecNormalize statistics {path} are a pickle, which can run code when it loads: "
        f"refused. If you trust the file, convert it once with `sgc convert --trust-model "
        f"{path}` (writes {path.with_suffix('.json').name}) or pass --trust-model"
    )


def load_statistics(path: str | Path, env: Any, trust_model: bool = False) -> Any:
    """The statistics at ``path`` as a ``VecNormalize`` for ``env`` (``training`` off).

    JSON is checked against ``env``'s observation space; a ``.pkl`` is unpickled only with
    ``trust_model`` (else a ValueError that says how to convert it).
    """
    file = Path(path)
    if file.suffix == ".pkl":
        if not trust_model:
            raise _refuse_pickle(file)
        with file.open("rb") as fh:
            vec_normalize = pickle.load(fh)  # noqa: S301 - the caller trusts this file
        if not hasattr(vec_normalize, "normalize_obs"):
            raise ValueError(f"VecNormalize statistics {file}: holds a "
                             f"{type(vec_normalize).__name__}, not a VecNormalize")  # fmt: skip
        vec_normalize.training = False
        return vec_normalize
    where = f"VecNormalize statistics {escaped(file)}"
    state = load_json(read_bounded(file, "VecNormalize statistics"), where)
    return _from_state(state, env, where)


def convert_pickle(path: str | Path) -> Path:
    """Rewrite a trusted ``.vecnormalize.pkl`` as JSON beside it (unpickles: trusted files only)."""
    file = Path(path)
    with file.open("rb") as fh:
        vec_normalize = pickle.load(fh)  # noqa: S301 - the caller vouches for the file
    return save_statistics(vec_normalize, file.with_suffix(".json"))
