"""Reading a file from elsewhere with bounded work, and quoting it safely in a message.

The one edge every text file from elsewhere passes (scenarios here; recipes, hyperparameters,
statistics, model metadata and benchmark results in ``baselines``): its size is checked
before it is read (:func:`read_bounded`), a YAML or JSON document's nesting and its number of
values (a YAML alias counted at each use) before anything walks it (:func:`check_tree`), and
every parser failure, ``RecursionError`` and ``MemoryError`` included, becomes one
:class:`FileLimitError` that names the file. Text from the file reaches a message only through
:func:`escaped`, so a newline or an ANSI escape in a file cannot forge a line of output.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

import yaml

from sgc_env.scenario.caps import CAPS, cap

__all__ = [
    "SAFE_LOADER",
    "FileLimitError",
    "check_count",
    "check_tree",
    "escaped",
    "load_json",
    "load_yaml",
    "read_bounded",
    "read_text",
]

_PARSE_FAILURES = (RecursionError, MemoryError, ValueError, OverflowError)
"""What Python's parsers raise on hostile text beside their own errors: deep nesting,
allocation failures, integers of more than 4300 digits."""


class FileLimitError(ValueError):
    """A file from elsewhere is unreadable, malformed or over a cap; the message names it."""


def escaped(text: object, limit: int = 200) -> str:
    """``text`` on one line: unprintable characters (newlines, ANSI escapes) written as
    Python escapes, and cut to ``limit`` characters."""
    s = str(text)
    cut = len(s) > limit
    s = s[:limit]
    s = "".join(c if c.isprintable() else repr(c)[1:-1] for c in s)
    return s + "..." if cut else s


def check_count(count: int, name: str, where: str) -> None:
    """``count`` within cap ``name`` (:data:`~sgc_env.scenario.caps.CAPS`), else a
    :class:`FileLimitError` starting with ``where`` (the file and field)."""
    item = CAPS[name]
    if count > item.limit:
        raise FileLimitError(
            f"{where}: {count} {item.unit}; at most {item.limit} ({item.reason})"
        )


def read_bounded(path: str | Path, what: str, limit_name: str = "file_bytes") -> bytes:
    """The bytes of ``path``, checked against cap ``limit_name`` before they are read
    (and again while reading: a file can grow)."""
    file = Path(path)
    where = f"{what} {escaped(file)}"
    try:
        size = file.stat().st_size
        if file.is_dir():
            raise FileLimitError(f"{where}: is a directory, not a file")
        check_count(size, limit_name, where)
        with file.open("rb") as fh:
            data = fh.read(cap(limit_name) + 1)
    except FileNotFoundError:
        raise FileLimitError(f"{where}: no such file") from None
    except OSError as exc:
        raise FileLimitError(f"{where}: cannot read: {escaped(exc.strerror or exc)}") from None
    check_count(len(data), limit_name, where)
    return data


def read_text(path: str | Path, what: str) -> str:
    """The UTF-8 text of ``path`` (:func:`read_bounded`), or a FileLimitError naming it."""
    data = read_bounded(path, what)
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise FileLimitError(f"{what} {escaped(path)}: not UTF-8 text (byte {exc.start}: "
                             f"{exc.reason}); save it as UTF-8") from None  # fmt: skip


def _walk(root: Any, children: Callable[[Any], Iterable[Any] | None], where: str) -> None:
    """Visit ``root`` and its descendants (``children``: None for a leaf) within the nesting
    and value caps; iterative, stopping at the first cap, so a self-referencing or
    alias-multiplied document costs at most ``data_nodes`` steps."""
    depth_cap, node_cap = cap("nesting"), cap("data_nodes")
    stack: list[tuple[Any, int]] = [(root, 1)]
    nodes = 0
    while stack:
        node, depth = stack.pop()
        nodes += 1
        if nodes > node_cap:
            check_count(nodes, "data_nodes", where)
        below = children(node)
        if below is not None:
            if depth > depth_cap:
                check_count(depth, "nesting", where)
            stack.extend((child, depth + 1) for child in below)


def _data_children(node: Any) -> Iterable[Any] | None:
    if isinstance(node, dict):
        return [x for pair in node.items() for x in pair]
    return node if isinstance(node, list | tuple) else None


def _yaml_children(node: yaml.Node) -> Iterable[yaml.Node] | None:
    if not isinstance(node, yaml.SequenceNode | yaml.MappingNode):
        return None
    return [x for item in node.value for x in (item if isinstance(item, tuple) else (item,))]


def check_tree(data: Any, where: str) -> Any:
    """``data`` once its nesting and its number of values are within the caps."""
    _walk(data, _data_children, where)
    return data


SAFE_LOADER: type = getattr(yaml, "CSafeLoader", yaml.SafeLoader)
"""PyYAML's safe loader, libyaml's where installed: its scanner and composer are C (the pure
Python scanner takes minutes on 100k nested brackets) and it stops at 1000 flow levels."""


def load_yaml(text: str, where: str, loader: type = SAFE_LOADER) -> Any:
    """Plain data of YAML ``text`` (a safe ``loader``), its graph checked against the
    nesting and value caps before it is constructed; any failure is a FileLimitError
    starting with ``where``."""
    check_count(len(text.encode("utf-8", "surrogatepass")), "yaml_bytes", where)
    try:
        reader = loader(text)
        try:
            node = reader.get_single_node()
            if node is None:
                return None
            _walk(node, _yaml_children, where)  # before construction, the slow step
            return reader.construct_document(node)
        finally:
            reader.dispose()
    except FileLimitError:
        raise
    except yaml.YAMLError as exc:
        raise FileLimitError(f"{where}: not valid YAML: {escaped(' '.join(str(exc).split()))}"
                             ) from None  # fmt: skip
    except RecursionError:
        raise FileLimitError(f"{where}: nested too deeply to read") from None
    except _PARSE_FAILURES as exc:
        raise FileLimitError(f"{where}: not valid YAML: {escaped(exc)}") from None


def load_json(text: str | bytes, where: str) -> Any:
    """Plain data of JSON ``text``, checked by :func:`check_tree`; any failure (bad JSON,
    nesting deeper than Python recurses, a 5000-digit integer, no memory) is a
    FileLimitError starting with ``where``."""
    check_count(len(text), "file_bytes", where)
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise FileLimitError(f"{where}: not valid JSON ({exc.msg} at {exc.pos})") from None
    except RecursionError:
        raise FileLimitError(f"{where}: nested too deeply to read") from None
    except _PARSE_FAILURES as exc:
        raise FileLimitError(f"{where}: not valid JSON ({escaped(exc)})") from None
    return check_tree(data, where)
