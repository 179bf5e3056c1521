"""Loading: a YAML path or a built-in name -> a resolved scenario; the one home of the built-in
folder and of the YAML loader.

YAML: the loader reads numbers as YAML 1.2 does, so ``1e0`` is the float 1.0 (plain YAML 1.1,
PyYAML's default, needs a dot and reads it as a string).
"""

from __future__ import annotations

import re
from importlib import resources
from importlib.abc import Traversable
from pathlib import Path
from typing import Any

import yaml

from sgc_env.scenario.bounded import FileLimitError, escaped, load_yaml, read_text
from sgc_env.scenario.model import Scenario, ScenarioError
from sgc_env.scenario.parse import scenario_from_dict
from sgc_env.scenario.resolve import resolve_scenario

__all__ = [
    "BUILTIN_DIR", "builtin_data", "builtin_path", "builtin_scenarios", "load_scenario",
    "read_yaml", "scenario_from_yaml",
]  # fmt: skip

BUILTIN_DIR = "builtin"
"""Folder of the built-in scenarios inside this package (package data of the wheel)."""


class _Loader(getattr(yaml, "CSafeLoader", yaml.SafeLoader)):  # type: ignore[misc]
    """PyYAML's safe loader (libyaml's when installed: ten times faster on ``three_rods``) with
    YAML 1.2 floats: ``1e0`` and ``1E-3`` are numbers (YAML 1.1 asks for a dot and reads them
    as strings, which surprises everyone). The one YAML loader of scenarios."""


_Loader.add_implicit_resolver(
    "tag:yaml.org,2002:float",
    re.compile(r"^[-+]?(?:[0-9][0-9_]*)(?:\.[0-9_]*)?[eE][-+]?[0-9]+$"),
    list("-+0123456789"),
)


def _builtin_root() -> Traversable:
    return resources.files("sgc_env.scenario") / BUILTIN_DIR


def builtin_path(name: str) -> Traversable:
    """Where the built-in scenario ``name`` lives (it may not exist)."""
    return _builtin_root() / f"{name}.yaml"


def builtin_scenarios() -> tuple[str, ...]:
    """Names of the scenarios shipped in ``sgc_env/scenario/builtin``."""
    root = _builtin_root()
    return tuple(sorted(p.name[:-5] for p in root.iterdir() if p.name.endswith(".yaml")))


def read_yaml(text: str, name: str) -> Any:
    """Plain data of a scenario's YAML text within the size, nesting and value caps
    (:mod:`sgc_env.scenario.bounded`), or a ScenarioError naming ``name``."""
    try:
        return load_yaml(text, escaped(name), _Loader)
    except FileLimitError as exc:
        raise ScenarioError(str(exc)) from None


def builtin_data(name: str) -> Any:
    """A built-in scenario's plain data (as written, not validated)."""
    res = builtin_path(name)
    if not res.is_file():
        raise ScenarioError(
            f"no scenario file {name!r} and no built-in of that name; "
            f"built-ins: {list(builtin_scenarios())}"
        )
    return read_yaml(res.read_text(encoding="utf-8"), name)


def load_scenario(path_or_name: str | Path | Scenario) -> Scenario:
    """Load, validate and resolve a scenario from a YAML path or a built-in name; a fault in
    a file is a ScenarioError that starts with the file and then names the field."""
    if isinstance(path_or_name, Scenario):
        return resolve_scenario(path_or_name)
    path = Path(path_or_name)
    if path.suffix in (".yaml", ".yml") and path.exists():
        return scenario_from_yaml(_read_text(path), path.stem, where=f"scenario {escaped(path)}")
    name = str(path_or_name)
    return _resolved(builtin_data(name), name)


def scenario_from_yaml(text: str, name: str = "scenario", where: str | None = None) -> Scenario:
    """The resolved scenario written in YAML ``text`` (``name``: its name unless it has one);
    any fault is a ScenarioError that starts with ``where`` (default: ``name``)."""
    return _resolved(read_yaml(text, where or name), name, where)


def _resolved(data: Any, name: str, where: str | None = None) -> Scenario:
    try:
        return resolve_scenario(scenario_from_dict(data, name=name))
    except RecursionError:  # a YAML alias can make a list that contains itself
        raise ScenarioError(f"{where or escaped(name)}: nested too deeply to read") from None
    except ScenarioError as exc:
        if where is None:
            raise
        raise ScenarioError(f"{where}: {exc}") from None


def _read_text(path: Path) -> str:
    """The file's text (size checked first), or a ScenarioError naming the file and what is
    wrong with it."""
    try:
        return read_text(path, "scenario")
    except FileLimitError as exc:
        raise ScenarioError(str(exc)) from None
