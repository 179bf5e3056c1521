"""The shipped models' manifest: ``baselines/checkpoints/manifest.json``, one entry per model.

Each entry says what the model is and how it came about (``file`` relative to the manifest,
``env_id``, ``algo``, ``demonstrations``, ``timesteps``, ``seed``, ``wall_time_s``,
``command``) and what it scores on held-out seeds (``result``). A model trained behind
``VecNormalize`` ships with its statistics as ``<stem>.vecnormalize.json`` beside it (plain
JSON, :mod:`baselines.models.normalization`; no pickle is shipped), which
:func:`baselines.policies.make_policy` restores. :func:`ship_model` copies a run's model in
and writes its entry (``scripts/ship_model.py`` is its command line).
"""

from __future__ import annotations

import json
import shutil
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from baselines.common.env_kwargs import check_env_kwargs
from sgc_env.scenario.bounded import load_json, read_bounded

__all__ = [
    "CHECKPOINTS",
    "ENTRY_FIELDS",
    "RESULT_KEYS",
    "check_manifest",
    "held_out_result",
    "load_manifest",
    "ship_model",
    "write_entry",
]

CHECKPOINTS = Path(__file__).resolve().parents[1] / "checkpoints"
MANIFEST_NAME = "manifest.json"
ENTRY_FIELDS: dict[str, type | tuple[type, ...]] = {
    "file": str, "env_id": str, "algo": str, "demonstrations": bool, "timesteps": int,
    "seed": int, "wall_time_s": (int, float), "command": str, "result": dict,
}  # fmt: skip
#: Scorecard keys kept in an entry's ``result`` (besides ``episodes`` and ``seed``).
RESULT_KEYS = ("n_goals", "goals_met", "success_rate", "position_error_mean",
               "position_error_max", "orientation_error_mean", "terminated")  # fmt: skip


def load_manifest(folder: str | Path = CHECKPOINTS) -> list[dict[str, Any]]:
    """The entries, each checked for its fields and types (``ValueError`` naming them)."""
    path = Path(folder) / MANIFEST_NAME
    if not path.is_file():
        return []
    entries = load_json(read_bounded(path, "manifest"), str(path))
    if not isinstance(entries, list):
        raise ValueError(f"{path}: expected a list of entries")
    for i, entry in enumerate(entries):
        where = f"{path}: entry {i}"
        if not isinstance(entry, dict):
            raise ValueError(f"{where}: expected an object")
        missing = sorted(set(ENTRY_FIELDS) - set(entry))
        if missing:
            raise ValueError(f"{where}: missing field(s) {missing}")
        for name, kind in ENTRY_FIELDS.items():
            value = entry[name]
            if not isinstance(value, kind) or (kind is int and isinstance(value, bool)):
                raise ValueError(f"{where}: {name} has type {type(value).__name__}")
    return entries


def check_manifest(folder: str | Path = CHECKPOINTS) -> list[str]:
    """Problems between the manifest and the folder (empty when they agree)."""
    root = Path(folder)
    entries = load_manifest(root)
    listed = [e["file"] for e in entries]
    problems = [f"{f}: listed twice" for f in sorted(set(listed)) if listed.count(f) > 1]
    problems += [f"{f}: listed, not in {root}" for f in listed if not (root / f).is_file()]
    present = sorted(p.name for p in root.glob("*.zip"))
    problems += [f"{f}: in {root}, not listed" for f in present if f not in listed]
    problems += [f"{p.name}: a pickle; ship statistics as JSON (sgc convert)"
                 for p in sorted(root.glob("*.pkl"))]  # fmt: skip
    return problems


def held_out_result(
    model: str | Path, env_id: str, episodes: int, seed: int, env_kwargs: Mapping | None = None
) -> dict[str, Any]:
    """Score ``model`` with the harness and keep the manifest's :data:`RESULT_KEYS`."""
    from baselines.evaluation.harness import evaluate, json_ready

    summary = evaluate(str(model), env_id, episodes, seed, env_kwargs=env_kwargs, keep_infos=0)
    return json_ready(
        {"episodes": episodes, "seed": seed, **{k: dict(summary.summary)[k] for k in RESULT_KEYS}}
    )


def write_entry(entry: Mapping[str, Any], folder: str | Path = CHECKPOINTS) -> Path:
    """Add ``entry`` to the manifest, replacing one for the same file."""
    missing = sorted(set(ENTRY_FIELDS) - set(entry))
    if missing:
        raise ValueError(f"manifest entry for {entry.get('file')!r}: missing {missing}")
    root = Path(folder)
    entries = [e for e in load_manifest(root) if e["file"] != entry["file"]]
    entries.append({name: entry[name] for name in ENTRY_FIELDS})
    entries.sort(key=lambda e: e["file"])
    path = root / MANIFEST_NAME
    path.write_text(json.dumps(entries, indent=1, allow_nan=False) + "\n")
    return path


def ship_model(
    run: str | Path,
    name: str,
    *,
    which: str = "best",
    episodes: int = 50,
    seed: int = 20_000,
    folder: str | Path = CHECKPOINTS,
) -> dict[str, Any]:
    """Copy ``run``'s best or final model in as ``<name>.zip``, score it, write its entry."""
    run_dir = Path(run)
    config_path = run_dir / "config.json"
    if not config_path.is_file():
        raise ValueError(f"run: no config.json in {run_dir} (a `sgc train --out` folder)")
    if which not in ("best", "final"):
        raise ValueError(f"which: expected 'best' or 'final', got {which!r}")
    source = run_dir / f"{which}_model.zip"
    if not source.is_file():
        raise ValueError(f"run: no {source.name} in {run_dir}")
    if (run_dir / "vecnormalize.pkl").is_file() and not (run_dir / "vecnormalize.json").is_file():
        raise ValueError(f"run: {run_dir}/vecnormalize.pkl is a pickle; convert it first "
                         "(sgc convert --trust-model, only for a run you trust)")  # fmt: skip
    config = load_json(read_bounded(config_path, "run config"), str(config_path))
    if not isinstance(config, dict) or not isinstance(config.get("train_config", {}), dict):
        raise ValueError(f"{config_path}: expected a `sgc train` config object")
    root = Path(folder)
    target = root / f"{name}.zip"
    shutil.copyfile(source, target)
    stats = run_dir / "vecnormalize.json"
    if stats.is_file():
        shutil.copyfile(stats, root / f"{name}.vecnormalize.json")
    command_file = run_dir / "command.txt"  # written by `sgc benchmark`, path resolved
    command = (read_bounded(command_file, "command").decode("utf-8", "replace").strip()
               if command_file.is_file() else config["command"])  # fmt: skip
    train_config = config.get("train_config", {})
    env_kwargs = train_config.get("env_kwargs") or None
    if env_kwargs is not None:
        check_env_kwargs(config["env_id"], env_kwargs, f"{config_path}: env_kwargs")
    entry = {
        "file": target.name, "env_id": config["env_id"], "algo": config["algo"],
        "demonstrations": train_config.get("init") == "bc",
        "timesteps": steps_trained(config), "seed": int(config["seed"]),
        "wall_time_s": round(float(config["wall_time_s"]), 1), "command": command,
        "result": held_out_result(target, config["env_id"], episodes, seed, env_kwargs),
    }  # fmt: skip
    write_entry(entry, root)
    return entry


def steps_trained(config: Mapping[str, Any]) -> int:
    """The env steps the model learned from: under a time budget ``timesteps`` is only the cap."""
    return int(config.get("steps_learned") or config.get("timesteps") or 0)
