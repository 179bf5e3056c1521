"""A ``sgc benchmark`` leaderboard pasted into a markdown document, between markers.

A document carries a leaderboard verbatim (its ``#`` title dropped, its env headings demoted to
``###``) between the lines ``<!-- NAME:begin -->`` and ``<!-- NAME:end -->``, so a rerun of
the benchmark updates it with one command (``sgc paste``).

Merging: a benchmark run of some recipes can update a pasted leaderboard of more. The merged
block is the leaderboard the union of both runs' ``--only`` lists would write: the same
``Reproduce`` command (``--only`` and ``--workers`` aside, or it is refused), each env's rows
of the new run in place of the pasted ones of the same recipe, rows and envs sorted by name as
the report sorts them.
"""

from __future__ import annotations

import shlex

__all__ = ["block", "leaderboard_body", "markers", "merge", "replace"]

_IGNORED = ("--only", "--workers")


def markers(name: str) -> tuple[str, str]:
    """The begin and end lines of the marker pair called ``name``."""
    return f"<!-- {name}:begin -->", f"<!-- {name}:end -->"


def leaderboard_body(text: str, where: str = "leaderboard") -> str:
    """The leaderboard without its ``#`` title, env headings as ``###``."""
    lines = text.strip().splitlines()
    if not lines or not lines[0].startswith("# "):
        raise ValueError(f"{where}: not a leaderboard.md of `sgc benchmark` (no '# ' title line)")
    body = [("#" + line) if line.startswith("## ") else line for line in lines[1:]]
    return "\n".join(body).strip()


def block(document: str, marker: str, where: str) -> str:
    """The text between the marker pair ``marker`` (``ValueError`` unless there is one pair)."""
    begin, end = markers(marker)
    if document.count(begin) != 1 or document.count(end) != 1:
        raise ValueError(f"{where}: needs exactly one {begin} and one {end} line")
    return document.split(begin)[1].split(end)[0].strip("\n")


def replace(document: str, marker: str, body: str, where: str) -> str:
    """``document`` with ``body`` between the marker pair ``marker``."""
    block(document, marker, where)
    begin, end = markers(marker)
    head, rest = document.split(begin)
    return f"{head}{begin}\n{body}\n{end}{rest.split(end)[1]}"


def _sections(body: str, where: str) -> tuple[list[str], dict[str, list[str]]]:
    """The lines before the first env heading, and each env's table lines (header first)."""
    preamble: list[str] = []
    tables: dict[str, list[str]] = {}
    current: list[str] | None = None
    for line in body.splitlines():
        if line.startswith("### "):
            current = tables.setdefault(line[4:].strip(), [])
        elif current is None:
            preamble.append(line)
        elif line.startswith("|"):
            current.append(line)
        elif line.strip():
            raise ValueError(f"{where}: unexpected line in a leaderboard table: {line!r}")
    for env_id, lines in tables.items():
        if len(lines) < 2:
            raise ValueError(f"{where}: the table of {env_id} has no header")
    return preamble, tables


def _command(preamble: list[str], where: str) -> tuple[list[str], list[str], list[str]]:
    """The ``Reproduce`` command's words; those words with the options a merge may differ in
    cut out (``--only``; ``--workers``, the pool's size, which changes no run); its ``--only``."""
    for line in preamble:
        if line.startswith("Reproduce: `") and line.endswith("`"):
            words = shlex.split(line[len("Reproduce: `") : -1])
            kept: list[str] = []
            only: list[str] = []
            pairs = iter(words)
            for word in pairs:
                option, _, value = word.partition("=")
                if option in _IGNORED:
                    value = value or next(pairs, "")
                    only = value.split(",") if option == "--only" else only
                else:
                    kept.append(word)
            if not only:
                raise ValueError(f"{where}: its Reproduce command has no --only list to merge")
            return words, kept, only
    raise ValueError(f"{where}: no 'Reproduce: `...`' line")


def _with_only(words: list[str], only: list[str]) -> list[str]:
    """``words`` with ``only`` as the ``--only`` list (``--only LIST`` or ``--only=LIST``)."""
    out: list[str] = []
    pairs = iter(words)
    for word in pairs:
        if word == "--only":
            out += [word, ",".join(only)]
            next(pairs, None)
        else:
            out.append("--only=" + ",".join(only) if word.startswith("--only=") else word)
    return out


def merge(pasted: str, new: str, where: str) -> str:
    """The leaderboard body of the union of two runs (module docstring): ``pasted`` the block
    a document holds, ``new`` the body of a leaderboard written since."""
    old_pre, old_tables = _sections(pasted, f"{where} (pasted)")
    new_pre, new_tables = _sections(new, f"{where} (new)")
    _, old_command, old_only = _command(old_pre, f"{where} (pasted)")
    new_words, new_command, new_only = _command(new_pre, f"{where} (new)")
    if old_command != new_command:
        raise ValueError(
            f"{where}: the leaderboards come from different commands (--only aside):\n"
            f"  pasted: {shlex.join(old_command)}\n  new:    {shlex.join(new_command)}"
        )
    only = old_only + [name for name in new_only if name not in old_only]
    reproduce = "Reproduce: `" + shlex.join(_with_only(new_words, only)) + "`"
    lines = [reproduce if line.startswith("Reproduce: `") else line
             for line in "\n".join(new_pre).strip().splitlines()]  # fmt: skip
    for env_id in sorted(old_tables.keys() | new_tables.keys()):
        old, fresh = old_tables.get(env_id, []), new_tables.get(env_id, [])
        if old and fresh and old[:2] != fresh[:2]:
            raise ValueError(f"{where}: the {env_id} tables have different columns")
        rows = {_recipe(row): row for row in old[2:]}
        rows.update({_recipe(row): row for row in fresh[2:]})
        lines += ["", f"### {env_id}", "", *(fresh or old)[:2], *(rows[k] for k in sorted(rows))]
    return "\n".join(lines).strip()


def _recipe(row: str) -> str:
    return row.strip("|").split("|")[0].strip()
