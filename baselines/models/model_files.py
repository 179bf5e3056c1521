"""Stable-Baselines3 model files from elsewhere, loaded without running code they may hold.

An SB3 ``.zip`` keeps in its ``data`` member, as cloudpickles, every attribute JSON cannot
hold (policy class, spaces, schedules, buffer classes ...), and unpickling runs whatever code
a file puts there. :func:`load_sb3_model` unpickles nothing: each pickled field is rebuilt
from what the JSON shows of it (SB3 writes the first-level attributes next to the pickle),
from the env (the spaces, after checking that the file's spaces fit it) or from
:func:`allowed_classes` (this project's and SB3's policies, features extractors, activations,
optimizers and buffers), and handed to SB3 through ``custom_objects``; SB3 loads the weights
with torch's ``weights_only=True``. Fields only training reads (schedules, the last rollout)
become constants or ``None``: a safely loaded model is for prediction.
``trust_model=True`` is SB3's own loading, which unpickles: for files one trusts.
"""

from __future__ import annotations

import functools
import importlib
import io
import json
import pickle
import re
import zipfile
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np

from sgc_env.scenario.bounded import (
    FileLimitError,
    check_count,
    escaped,
    load_json,
    read_bounded,
)
from sgc_env.scenario.caps import cap

__all__ = [
    "EARLIER_MODULES",
    "ModelFileError",
    "TRUST_WARNING",
    "algorithm_from_data",
    "allowed_classes",
    "load_sb3_model",
    "read_model_data",
]

TRUST_WARNING = (
    "--trust-model unpickles model files: a file can run any code on this machine while it "
    "loads. Use it only for files you made or whose source you trust."
)
_CLASS_REPR = re.compile(r"<class '([\w.]+)'>")
_FUNCTION_OWNER = re.compile(r"<function ([\w.]+)\.\w+ at 0x[0-9a-f]+>")
#: ``'key': Box(low, high, (shape,), dtype)`` in a Dict space's repr; ``[^()]*`` where a lazy
#: ``.*?`` would try every later position (time growing with the square of the text).
_DICT_SPACE = re.compile(r"'(\w+)': \w+\([^()]*?, \(([\d, ]*)\), (\w+)\)")
_NUMBER = r"[-+]?(?:\d+\.?\d*(?:e[-+]?\d+)?|inf|nan)"
_SCHEDULE_VALUE = re.compile(rf"(?:val|start|initial_value)=({_NUMBER})")
#: Fields SB3 saves from the last rollout or for training only; ``None`` restarts them.
_RUNTIME_STATE = ("_last_obs", "_last_original_obs", "_last_episode_starts", "ep_info_buffer",
                  "ep_success_buffer", "action_noise")  # fmt: skip
_SCHEDULES = ("lr_schedule", "learning_rate", "clip_range", "clip_range_vf")
_CLASS_FIELDS = ("policy_class", "rollout_buffer_class", "replay_buffer_class")
_KWARGS_FIELDS = ("policy_kwargs", "rollout_buffer_kwargs", "replay_buffer_kwargs")
class ModelFileError(ValueError):
    """A model file that is malformed, does not fit the env, or would need unpickling."""


@functools.cache
def allowed_classes() -> dict[str, type]:
    """``module.QualName`` -> class, for every class a model file may name."""
    import torch as th
    from stable_baselines3 import HerReplayBuffer
    from stable_baselines3.common import buffers, policies, torch_layers
    from stable_baselines3.sac import policies as sac
    from stable_baselines3.td3 import policies as td3

    from baselines.models.features import ACTIVATIONS, StandardizeObservation
    from baselines.models.per_body import LearnerViewBodies, PerBodyPolicy

    classes: list[type] = [
        policies.ActorCriticPolicy, policies.ActorCriticCnnPolicy,
        policies.MultiInputActorCriticPolicy, PerBodyPolicy, sac.SACPolicy, sac.CnnPolicy,
        sac.MultiInputPolicy,
        td3.TD3Policy, td3.CnnPolicy, td3.MultiInputPolicy,
        torch_layers.FlattenExtractor, torch_layers.NatureCNN, torch_layers.CombinedExtractor,
        StandardizeObservation, LearnerViewBodies,
        *(getattr(th.nn, name) for name in ACTIVATIONS),
        th.optim.Adam, th.optim.AdamW, th.optim.RMSprop, th.optim.SGD,
        buffers.RolloutBuffer, buffers.DictRolloutBuffer, buffers.ReplayBuffer,
        buffers.DictReplayBuffer, HerReplayBuffer,
    ]  # fmt: skip
    return {f"{c.__module__}.{c.__qualname__}": c for c in classes}


def _fail(path: str, problem: str) -> ModelFileError:
    return ModelFileError(f"model file {escaped(path, 400)}: {problem}")


#: The ``.pth`` members SB3's algorithms write (PPO/A2C: policy and its optimizer; SAC/TD3:
#: the actor's and critics' optimizers, SAC's entropy coefficient's).
_WEIGHT_MEMBERS = frozenset({"policy.pth", "policy.optimizer.pth", "pytorch_variables.pth",
                             "actor.optimizer.pth", "critic.optimizer.pth",
                             "ent_coef_optimizer.pth"})  # fmt: skip
#: The tensors SB3 keeps in ``pytorch_variables.pth`` (SAC's entropy coefficient); SB3 sets
#: each key as an attribute path of the model, so no other key may reach it.
_TORCH_VARIABLES = frozenset({"log_ent_coef", "ent_coef_tensor"})


def _read_member(archive: zipfile.ZipFile, info: zipfile.ZipInfo, path: str) -> bytes:
    """A member's bytes, read no further than the cap (a member may lie about its size)."""
    limit = cap("zip_member_bytes" if info.filename != "data" else "file_bytes")
    with archive.open(info) as member:
        blob = member.read(limit + 1)
    check_count(len(blob), "zip_member_bytes" if info.filename != "data" else "file_bytes",
                f"model file {path}: member {escaped(info.filename)!r}")  # fmt: skip
    return blob


def read_model_data(blob: bytes, path: str) -> tuple[dict[str, Any], list[str]]:
    """The JSON of the zip's ``data`` member (nothing unpickled) and the member names."""
    data, members = _read_members(blob, path)
    return data, list(members)


def _read_members(blob: bytes, path: str) -> tuple[dict[str, Any], dict[str, bytes]]:
    """The JSON of the ``data`` member and every member's bytes; the members' number and
    declared sizes are checked against the caps before any is read."""
    members: dict[str, bytes] = {}
    try:
        with zipfile.ZipFile(io.BytesIO(blob)) as archive:
            infos = archive.infolist()
            names = [i.filename for i in infos]
            check_count(len(infos), "zip_members", f"model file {path}: members")
            for info in infos:
                check_count(info.file_size, "zip_member_bytes",
                            f"model file {path}: member {escaped(info.filename)!r}")  # fmt: skip
            check_count(sum(i.file_size for i in infos), "model_file_bytes",
                        f"model file {path}: members in all")  # fmt: skip
            missing = [m for m in ("data", "policy.pth") if m not in names]
            if missing:
                raise _fail(path, f"missing member(s) {missing}: not a Stable-Baselines3 model")
            for info in infos:  # reads every member once: a truncated or corrupt one fails here
                members[info.filename] = _read_member(archive, info, path)
    except FileLimitError as exc:
        raise ModelFileError(str(exc)) from None
    except (zipfile.BadZipFile, EOFError, OSError) as exc:
        raise _fail(path, f"not a readable zip archive (truncated or corrupt: "
                          f"{escaped(exc)})") from None  # fmt: skip
    except (ValueError, RuntimeError, MemoryError) as exc:  # zlib / CRC errors inside a member
        if isinstance(exc, ModelFileError):
            raise
        raise _fail(path, f"corrupt member ({escaped(exc)})") from None
    try:
        data = load_json(members["data"], f"model file {path}: member 'data'")
    except FileLimitError as exc:
        raise ModelFileError(str(exc)) from None
    if not isinstance(data, dict):
        raise _fail(path, "member 'data' is not a JSON object")
    return data, members


def _check_weight_members(members: dict[str, bytes], path: str) -> None:
    """Only SB3's ``.pth`` members, and ``pytorch_variables.pth`` only SB3's own tensors:
    SB3 turns member names and that file's keys into attribute paths of the model."""
    import torch as th

    foreign = sorted(n for n in members if n.endswith(".pth") and n not in _WEIGHT_MEMBERS)
    if foreign:
        raise _fail(path, f"member(s) {escaped(foreign)} are not weights SB3 writes "
                          f"(known: {sorted(_WEIGHT_MEMBERS)})")  # fmt: skip
    if "pytorch_variables.pth" not in members:
        return
    try:
        variables = th.load(io.BytesIO(members["pytorch_variables.pth"]), map_location="cpu",
                            weights_only=True)  # fmt: skip
    except (pickle.UnpicklingError, RuntimeError, ValueError, EOFError, MemoryError) as exc:
        first = escaped(str(exc).strip().splitlines()[0] if str(exc).strip() else exc)
        raise _fail(path, f"member 'pytorch_variables.pth' is not plain tensors ({first})"
                    ) from None  # fmt: skip
    if not isinstance(variables, dict):
        raise _fail(path, "member 'pytorch_variables.pth' is not a mapping of tensors")
    for key, value in variables.items():
        if key not in _TORCH_VARIABLES or not (value is None or isinstance(value, th.Tensor)):
            raise _fail(path, f"pytorch_variables.pth: key {escaped(repr(key))} is not one of "
                              f"SB3's tensors {sorted(_TORCH_VARIABLES)}")  # fmt: skip


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


def _pickled(value: Any) -> bool:
    return isinstance(value, dict) and ":serialized:" in value


#: Modules that held this project's model classes before 1.0 (the features computed inside the
#: policy for the planner's view): a file naming one is a model of an earlier id.
EARLIER_MODULES = ("baselines.agents.features", "baselines.agents.schedule_features",
                   "baselines.agents.per_body", "baselines.models.schedule_features")  # fmt: skip


def _named_class(dotted: str, where: str, path: str) -> type:
    cls = allowed_classes().get(dotted)
    if cls is None and dotted.rpartition(".")[0] in EARLIER_MODULES:
        raise _fail(path, f"{where} names class {dotted!r} of sgc before 1.0, a model of an "
                          "earlier env version; train a new one on the current id (CHANGELOG.md, "
                          "'Migrating to 1.0')")  # fmt: skip
    if cls is None:
        raise _fail(path, f"{where} names class {dotted!r}, which is not on the allow-list of "
                          "this project's and SB3's classes; load it with --trust-model only if "
                          "you trust the file")  # fmt: skip
    return cls


def _class_field(entry: dict[str, Any], key: str, path: str) -> type:
    """The class a pickled class field stands for: its module plus the owner of its methods."""
    owners = {m[1] for v in entry.values() if isinstance(v, str)
              for m in [_FUNCTION_OWNER.fullmatch(v)] if m}  # fmt: skip
    module = entry.get("__module__")
    if len(owners) != 1 or not isinstance(module, str):
        raise _fail(path, f"field {key!r}: cannot tell which class it holds without unpickling")
    return _named_class(f"{module}.{owners.pop()}", f"field {key!r}", path)


def _kwargs_field(entry: dict[str, Any], key: str, path: str) -> dict[str, Any]:
    """A pickled kwargs dict from its visible items: JSON values, and classes by name."""
    if entry.get(":type:") != "<class 'dict'>":
        raise _fail(path, f"field {key!r} holds a pickled {entry.get(':type:')}, not a dict")
    out: dict[str, Any] = {}
    for name, value in entry.items():
        if name.startswith(":"):
            continue
        if isinstance(value, str) and value.startswith("<"):
            match = _CLASS_REPR.fullmatch(value)
            if match is None:
                raise _fail(path, f"{key}[{name!r}] is {value!r}, which only unpickling restores")
            value = _named_class(match[1], f"{key}[{name!r}]", path)
        out[name] = value
    return out


def _schedule_field(entry: Any, key: str, data: dict[str, Any]) -> Any:
    """A constant schedule: the value the file shows, else the plain learning rate, else 0."""
    from stable_baselines3.common.utils import ConstantSchedule, FloatSchedule

    shown = json.dumps(entry) if isinstance(entry, dict) else ""
    match = _SCHEDULE_VALUE.search(shown)
    if match is not None:
        value = float(match[1])
    elif key in ("lr_schedule", "learning_rate") and isinstance(data.get("learning_rate"), float):
        value = data["learning_rate"]
    else:
        value = 0.0
    return value if key == "learning_rate" else FloatSchedule(ConstantSchedule(value))


def _box_summary(entry: dict[str, Any]) -> str:
    return f"Box(shape={tuple(entry.get('_shape') or ())}, {entry.get('dtype')})"


def _bounds_fit(text: Any, bounds: np.ndarray) -> bool:
    """The file's printed bounds against the env's (skipped when numpy elided them)."""
    if not isinstance(text, str) or "..." in text:
        return True
    try:
        values = np.array([float(v) for v in text.replace("[", " ").replace("]", " ").split()])
    except ValueError:
        return True
    if values.size != bounds.size:
        return False
    return bool(np.allclose(values, bounds.ravel().astype(float), rtol=1e-6, atol=0.0))


def _space_field(entry: Any, key: str, env_space: gym.Space, path: str) -> gym.Space:
    """The env's space, once the file's recorded space is seen to fit it."""
    kind = f"{type(env_space).__module__}.{type(env_space).__qualname__}"
    if not isinstance(entry, dict):
        raise _fail(path, f"field {key!r} is not a recorded space")
    recorded = _CLASS_REPR.fullmatch(str(entry.get(":type:", "")))
    name = key.replace("_", " ")
    if recorded is None or recorded[1] != kind:
        got = recorded[1].rsplit(".", 1)[-1] if recorded else entry.get(":type:")
        return _mismatch(path, name, str(got), env_space)
    if isinstance(env_space, gym.spaces.Box):
        fits = (
            list(entry.get("_shape") or []) == list(env_space.shape)
            and entry.get("dtype") == str(env_space.dtype)
            and _bounds_fit(entry.get("low"), env_space.low)
            and _bounds_fit(entry.get("high"), env_space.high)
        )
        if not fits:
            return _mismatch(path, name, _box_summary(entry), env_space)
    elif isinstance(env_space, gym.spaces.Dict):
        shown = _DICT_SPACE.findall(str(entry.get("spaces"))[: cap("file_bytes")])
        mine = [(k, ", ".join(map(str, s.shape or ())) + ("," if len(s.shape or ()) == 1 else ""),
                 str(s.dtype)) for k, s in env_space.spaces.items()]  # fmt: skip
        if shown and sorted(shown) != sorted(mine):
            return _mismatch(path, name, str(entry.get("spaces")), env_space)
    return env_space


def _mismatch(path: str, name: str, recorded: str, env_space: gym.Space) -> Any:
    raise _fail(path, f"its {name} {escaped(recorded)} does not fit this env's {env_space}"
                      f"{_trained_on(path)}")  # fmt: skip


def _trained_on(path: str) -> str:
    """`` (trained on ID)`` from a ``config.json`` or ``manifest.json`` beside the file (read
    within the caps; its text escaped)."""
    folder, name = Path(path).parent, Path(path).name
    try:
        config = folder / "config.json"
        if config.is_file():
            env_id = load_json(read_bounded(config, "config"), str(config))["env_id"]
            return f" (trained on {escaped(env_id, 80)})"
        manifest = folder / "manifest.json"
        if manifest.is_file():
            entries = load_json(read_bounded(manifest, "manifest"), str(manifest))
            return next(f" (trained on {escaped(e['env_id'], 80)})" for e in entries
                        if e["file"] == name)  # fmt: skip
    except (ValueError, KeyError, TypeError, StopIteration, OSError):
        pass
    return ""


def safe_custom_objects(
    data: dict[str, Any], env: Any, path: str, algorithm: type
) -> dict[str, Any]:
    """A replacement for every pickled field of ``data`` (:class:`ModelFileError` when one
    cannot be rebuilt without unpickling, or when a field would shadow one of
    ``algorithm``'s methods: SB3 sets every field as an attribute of the model)."""
    objects: dict[str, Any] = {}
    for key, entry in data.items():
        if key.startswith("__") or callable(getattr(algorithm, key, None)):
            raise _fail(path, f"field {key!r} is not a model attribute (it would replace "
                              f"{algorithm.__name__}.{key})")  # fmt: skip
        if key in ("observation_space", "action_space"):
            objects[key] = _space_field(entry, key, getattr(env, key), path)
        elif not _pickled(entry):
            continue
        elif key in _CLASS_FIELDS:
            objects[key] = _class_field(entry, key, path)
        elif key in _KWARGS_FIELDS:
            objects[key] = _kwargs_field(entry, key, path)
        elif key in _SCHEDULES:
            objects[key] = _schedule_field(entry, key, data)
        elif key in _RUNTIME_STATE:
            objects[key] = None
        elif key == "train_freq":
            objects[key] = (1, "step")  # training only; the file's value needs unpickling
        else:
            raise _fail(path, f"field {key!r} holds a pickled {entry.get(':type:')} that this "
                              "loader does not rebuild; load it with --trust-model only if you "
                              "trust the file")  # fmt: skip
    return objects


def _check_network(data: dict[str, Any], env: Any, path: str) -> None:
    """The network sizes the file's ``policy_kwargs`` shows (:mod:`baselines.common.network_caps`),
    before SB3 builds them."""
    from baselines.common.network_caps import check_policy_kwargs

    kwargs = data.get("policy_kwargs")
    if not isinstance(kwargs, dict):
        return
    space = getattr(env, "observation_space", None)
    inputs = int(np.prod(space.shape)) if isinstance(space, gym.spaces.Box) else 1
    try:
        check_policy_kwargs(kwargs, "policy_kwargs", inputs)
    except ValueError as exc:
        raise _fail(path, str(exc)) from None


def load_sb3_model(
    path: str | Path, env: Any | None = None, device: str = "cpu", trust_model: bool = False
) -> Any:
    """Load a Stable-Baselines3 model zip, detecting its algorithm (see the module docstring).

    Safe loading (the default) needs ``env``: the spaces are the env's, once the file's are
    seen to fit; a HER model also needs it for its replay buffer.
    """
    file = Path(path)
    name = str(path)
    if not file.is_file():
        raise ValueError(f"policy: model file {name!r} "
                         f"{'is a folder' if file.is_dir() else 'does not exist'}")  # fmt: skip
    try:
        blob = read_bounded(file, "model file", "model_file_bytes")  # once: what is checked loads
    except FileLimitError as exc:
        raise ModelFileError(str(exc)) from None
    data, members = _read_members(blob, name)
    try:
        algo = algorithm_from_data(data)
    except ValueError as exc:
        raise _fail(name, escaped(exc)) from None
    _check_network(data, env, name)
    algorithm = getattr(importlib.import_module("stable_baselines3"), algo)
    if trust_model:
        objects = None
    elif env is None:
        raise _fail(name, "safe loading rebuilds the spaces from the env: pass env")
    else:
        objects = safe_custom_objects(data, env, name, algorithm)
        _check_weight_members(members, name)
    try:
        model = algorithm.load(io.BytesIO(blob), env=env, device=device, custom_objects=objects)
    except pickle.UnpicklingError as exc:
        first = escaped(str(exc).splitlines()[0])
        raise _fail(name, "its weights hold objects other than tensors, refused by torch's "
                          f"weights_only loading ({first})") from None  # fmt: skip
    except (RuntimeError, KeyError, TypeError, AssertionError, ValueError, AttributeError,
            MemoryError, RecursionError) as exc:  # fmt: skip
        first = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise _fail(name, f"does not load as a {algo} for this env: {escaped(first)}") from None
    bind = getattr(model.policy, "bind_env", None)
    if env is not None and bind is not None:  # PerBodyPolicy: the env's action gains
        bind(env)
    return model
