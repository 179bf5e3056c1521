"""Every ``sgc`` command the README and docs/ show exists and answers ``--help``: a page cannot
send a user to a command (or a ``sgc bench`` benchmark) that the installed package lacks."""

from __future__ import annotations

import argparse
import re
from pathlib import Path

import pytest

from baselines.cli.main import COMMANDS, build_parser, main

ROOT = Path(__file__).resolve().parents[3]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]
SHOWN = re.compile(r"(?:\.venv/bin/sgc|`sgc) ([a-z][a-z-]*)(?: ([a-z]+))?")


def _nested() -> dict[str, set[str]]:
    """The commands whose first word picks a sub-command (``sgc bench env``), and those words."""
    nested: dict[str, set[str]] = {}
    for action in build_parser()._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, command in action.choices.items():
                for inner in command._actions:
                    if isinstance(inner, argparse._SubParsersAction):
                        nested[name] = set(inner.choices)
    return nested


NESTED = _nested()


def _documented() -> set[tuple[str, ...]]:
    shown: set[tuple[str, ...]] = set()
    for page in PAGES:
        for command, word in SHOWN.findall(page.read_text()):
            shown.add((command, word) if command in NESTED and word else (command,))
    return shown


DOCUMENTED = sorted(_documented())


def test_the_pages_show_commands() -> None:
    assert {("evaluate",), ("demo",), ("bench", "env"), ("paste",)} <= set(DOCUMENTED)


@pytest.mark.parametrize("words", DOCUMENTED, ids=" ".join)
def test_a_documented_command_answers_help(words: tuple[str, ...], capsys) -> None:
    assert words[0] in COMMANDS, f"the docs show `sgc {' '.join(words)}`, which is no command"
    if words[0] in NESTED and len(words) > 1:
        assert words[1] in NESTED[words[0]], f"`sgc {' '.join(words)}` is no benchmark"
    assert main([*words, "--help"]) == 0
    assert capsys.readouterr().out.startswith(f"usage: sgc {' '.join(words)}")
