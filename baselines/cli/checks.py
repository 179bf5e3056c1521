"""Argument checks for the ``sgc`` commands, and outputs that appear only when a run finishes.

The ``argparse`` types here reject a bad value before any work starts, with argparse's own
one-line error and exit status 2. :class:`UsageError` is for checks that need more than one
argument or an import (env ids, JSON); ``sgc``'s ``main`` turns it into the same one line.
:func:`staged_output` writes a run into a temporary folder next to ``--out`` and moves the
files into place at the end, so an interrupted run leaves the earlier results whole.
"""

from __future__ import annotations

import argparse
import contextlib
import math
import os
import shutil
import sys
import tempfile
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

__all__ = [
    "UsageError",
    "add_trust_argument",
    "error_exit",
    "bounded_int",
    "env_kwargs",
    "existing_dir",
    "existing_file",
    "fraction",
    "known_env_id",
    "nonneg_float",
    "nonneg_int",
    "out_dir",
    "out_file",
    "positive_float",
    "positive_int",
    "staged_output",
    "trust_model",
]


class UsageError(ValueError):
    """A command-line argument is wrong; ``sgc`` prints the message and exits 2."""


def error_exit(command: str, exc: BaseException | str) -> int:
    """Print ``sgc COMMAND: error: MESSAGE`` on one line of stderr and return 2. The message
    is escaped: text it quotes from a file (a newline, a terminal escape) cannot start a line
    of its own or forge one."""
    from sgc_env.scenario.bounded import escaped

    print(f"sgc {command}: error: {escaped(exc, 2000)}", file=sys.stderr)
    return 2


def _number(kind: Callable[[str], Any], text: str) -> Any:
    try:
        value = kind(text)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected {'an integer' if kind is int else 'a number'}, got {text!r}"
        ) from None
    if kind is float and not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"expected a finite number, got {text!r}")
    return value


def bounded_int(low: int, high: int | None = None) -> Callable[[str], int]:
    """An integer in ``[low, high]``."""

    def parse(text: str) -> int:
        value = _number(int, text)
        if value < low or (high is not None and value > high):
            span = f">= {low}" if high is None else f"in [{low}, {high}]"
            raise argparse.ArgumentTypeError(f"expected an integer {span}, got {value}")
        return value

    return parse


nonneg_int = bounded_int(0)
positive_int = bounded_int(1)


def nonneg_float(text: str) -> float:
    value = _number(float, text)
    if value < 0:
        raise argparse.ArgumentTypeError(f"expected a number >= 0, got {value}")
    return value


def positive_float(text: str) -> float:
    value = _number(float, text)
    if value <= 0:
        raise argparse.ArgumentTypeError(f"expected a number > 0, got {value}")
    return value


def fraction(text: str) -> float:
    value = _number(float, text)
    if not 0.0 <= value <= 1.0:
        raise argparse.ArgumentTypeError(f"expected a number in [0, 1], got {value}")
    return value


def _probe(folder: Path) -> None:
    """Create and delete a file in ``folder`` (permission bits do not tell, e.g. for root)."""
    try:
        with tempfile.TemporaryFile(dir=folder):
            pass
    except OSError as exc:
        raise argparse.ArgumentTypeError(
            f"cannot write in {folder}: {exc.strerror or exc}"
        ) from None


def _writable_parent(path: Path) -> None:
    """The nearest existing folder above ``path`` must be a folder we can write in."""
    parent = path.absolute().parent
    while not parent.exists():
        parent = parent.parent
    if not parent.is_dir():
        raise argparse.ArgumentTypeError(f"{parent} is a file, so {path} cannot be created")
    _probe(parent)


def out_dir(text: str) -> Path:
    """An output folder: absent (it will be created) or a folder we can write in."""
    path = Path(text)
    if path.exists() and not path.is_dir():
        raise argparse.ArgumentTypeError(f"{path} exists and is not a folder")
    if path.is_dir():
        _probe(path)
    _writable_parent(path)  # created there, and the staged copy is made next to it
    return path


def out_file(text: str) -> Path:
    """An output file: not a folder, in a folder we can write in."""
    path = Path(text)
    if path.is_dir():
        raise argparse.ArgumentTypeError(f"{path} is a folder; give a file name")
    _writable_parent(path)
    return path


def existing_file(text: str) -> Path:
    path = Path(text)
    if not path.is_file():
        raise argparse.ArgumentTypeError(f"no such file: {path}")
    return path


def existing_dir(text: str) -> Path:
    path = Path(text)
    if not path.is_dir():
        raise argparse.ArgumentTypeError(f"no such folder: {path}")
    return path


def known_env_id(env_id: str) -> str:
    """A registered id (``sgc_env.check_env_id``), else a UsageError naming ``--env``."""
    import sgc_env

    try:
        return sgc_env.check_env_id(env_id, "--env")
    except ValueError as exc:
        raise UsageError(str(exc)) from None


def env_kwargs(text: str) -> dict[str, Any]:
    """A JSON object (keyword arguments for ``gym.make``), read within the caps."""
    from sgc_env.scenario.bounded import FileLimitError, escaped, load_json

    try:
        value = load_json(text, "JSON")
    except FileLimitError as exc:
        raise argparse.ArgumentTypeError(str(exc).removeprefix("JSON: ")) from None
    if not isinstance(value, dict):
        raise argparse.ArgumentTypeError(f"expected a JSON object, got {escaped(repr(text))}")
    return value


def _real_folder(out: Path, relative: Path) -> Path:
    """``out / relative`` as a real folder: a link met on the way (to a folder elsewhere,
    or dangling) is replaced by a folder, never written through."""
    out.mkdir(parents=True, exist_ok=True)
    folder = out
    for part in relative.parts:
        folder = folder / part
        if folder.is_symlink() or (folder.exists() and not folder.is_dir()):
            folder.unlink()
        folder.mkdir(exist_ok=True)
    return folder


def _move_files(stage: Path, out: Path, folder: str = "") -> None:
    """Move the staged files into ``out``; ``os.replace`` puts each file in place of a file
    or a link of its name (it never writes through a link), and :func:`_real_folder` does
    the same for the folders on the way."""
    for src in sorted(p for p in (stage / folder).rglob("*") if p.is_file()):
        relative = src.relative_to(stage)
        os.replace(src, _real_folder(out, relative.parent) / relative.name)


@contextlib.contextmanager
def staged_output(out: Path, keep_on_failure: tuple[str, ...] = ()) -> Iterator[Path]:
    """A fresh temporary folder inside ``out`` to write into (nothing is written outside
    ``out``); on success its files replace those of the same name under ``out`` (others there
    are kept), on any failure or interrupt it is removed and ``out`` keeps its files, except
    for the subfolders ``keep_on_failure`` (e.g. a training run's checkpoints, new files that
    replace nothing whole)."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    stage = Path(tempfile.mkdtemp(prefix=".partial-", dir=out))
    try:
        yield stage
        _move_files(stage, out)
    except BaseException:
        for folder in keep_on_failure:
            _move_files(stage, out, folder)
        raise
    finally:
        shutil.rmtree(stage, ignore_errors=True)


def add_trust_argument(parser: argparse.ArgumentParser) -> None:
    """``--trust-model``: load model files with SB3's unpickling (see
    baselines.models.model_files)."""
    parser.add_argument(
        "--trust-model", action="store_true",
        help="unpickle model files (.zip fields, .vecnormalize.pkl) as SB3 does: a file can "
        "run any code while it loads; only for files you made or trust. Default: load "
        "without unpickling",
    )  # fmt: skip


def trust_model(args: argparse.Namespace, command: str) -> bool:
    """``args.trust_model``, printing the risk to stderr when it is set."""
    trust = bool(getattr(args, "trust_model", False))
    if trust:
        from baselines.models.model_files import TRUST_WARNING

        print(f"sgc {command}: warning: {TRUST_WARNING}", file=sys.stderr)
    return trust
