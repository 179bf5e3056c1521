"""Presentation shared by the commands: help with defaults, the one-line result summary, and
a console sized to the person's terminal (or, in a log, wide enough for every number)."""

from __future__ import annotations

import argparse
import math
import os
import sys
from collections.abc import Mapping
from typing import Any

__all__ = ["DefaultsHelpFormatter", "make_console", "summary_line"]

WIDE_WIDTH = 240
"""Console width of ``--wide`` output (lines longer than the terminal wrap, cells stay whole)."""

LOG_WIDTH = 1000
"""Console width when stdout is a file or a pipe and ``COLUMNS`` is unset: wider than any of
our tables, so a CI log or a redirected run keeps every cell whole instead of Rich's default
80 columns, which squeezes numbers to "2.0…". Tables are as wide as their content, not this."""


class DefaultsHelpFormatter(argparse.ArgumentDefaultsHelpFormatter):
    """``--help`` shows each option's default, except the uninformative None and False."""

    def _get_help_string(self, action: argparse.Action) -> str:
        text = action.help or ""
        default = action.default
        if default is None or default is False or default == argparse.SUPPRESS:
            return text
        if "%(default)" in text:
            return text
        return super()._get_help_string(action) or text


def make_console(wide: bool = False) -> Any:
    """A Rich console: ``WIDE_WIDTH`` with ``wide``; else the terminal's width, or ``COLUMNS``
    where it is set, or ``LOG_WIDTH`` when stdout is not a terminal (a log keeps every digit)."""
    from rich.console import Console

    if wide:
        return Console(width=WIDE_WIDTH)
    if sys.stdout.isatty() or os.environ.get("COLUMNS"):
        return Console()
    return Console(width=LOG_WIDTH)


def _number(value: Any, spec: str, unit: str) -> str:
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return "-"
    return f"{format(value, spec)} {unit}"


def summary_line(summary: Mapping[str, Any]) -> str:
    """Goals met, success and the largest errors of a harness scorecard, for a person."""
    text = (
        f"{int(summary.get('goals_met', 0))}/{int(summary.get('n_goals', 0))} goals met, "
        f"success {summary.get('success_rate', 0.0):.2f}, "
        f"max error {_number(summary.get('position_error_max'), '.1e', 'm')}"
    )
    orientation = summary.get("orientation_error_max")
    if isinstance(orientation, float) and math.isfinite(orientation):
        text += f", {_number(orientation, '.1e', 'rad')}"
    if summary.get("terminated"):
        text += f", {int(summary['terminated'])} episode(s) failed (left the workspace or diverged)"
    return text
