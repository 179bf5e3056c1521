"""Presentation shared by the commands: help with defaults, the one-line result summary, a
console sized to the person's terminal (or, in a log, wide enough for every number), the
scorecard tables printed on it, and the progress of a benchmark's runs; what a training run did."""

from __future__ import annotations

import argparse
import math
import os
import sys
from collections.abc import Mapping, Sequence
from typing import Any

__all__ = [
    "COMPACT_COLUMNS",
    "DefaultsHelpFormatter",
    "RunProgress",
    "SMOOTHNESS_COLUMNS",
    "SMOOTHNESS_WIDE_COLUMNS",
    "demo_scorecard_table",
    "goal_table",
    "goals_met_line",
    "make_console",
    "smoothness_line",
    "print_training",
    "scorecard_table",
    "summary_line",
]

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


#: The default table, readable at 80 columns (``--wide``: every column of
#: :data:`baselines.evaluation.scorecards.SCORECARD_COLUMNS`).
COMPACT_COLUMNS: tuple[tuple[str, str, str], ...] = (
    ("env_id", "env", "s"),
    ("policy", "policy", "s"),
    ("success_rate", "success", ".2f"),
    ("position_error_max", "pos err\nmax (m)", ".1e"),
    ("orientation_error_max", "ori err\nmax (rad)", ".1e"),
    ("position_closest_offset_abs_max", "offset\nmax (s)", ".3f"),
)

#: The smoothness table printed under the compact one: LDLJ over the whole track and the
#: largest one-tick change of acceleration (the kink), linear and angular (peaks: ``--wide``).
SMOOTHNESS_COLUMNS: tuple[tuple[str, str, str], ...] = (
    ("env_id", "env", "s"),
    ("policy", "policy", "s"),
    ("ldlj_track_mean", "LDLJ\ntrack", ".2f"),
    ("acceleration_kink_max", "kink\n(m/s²)", ".2f"),
    ("angular_ldlj_track_mean", "ang LDLJ\ntrack", ".2f"),
    ("angular_acceleration_kink_max", "ang kink\n(rad/s²)", ".2f"),
)

#: The smoothness table with ``--wide``: peaks and the angular velocity jump too.
SMOOTHNESS_WIDE_COLUMNS: tuple[tuple[str, str, str], ...] = (
    *SMOOTHNESS_COLUMNS[:4],
    ("acceleration_peak_max", "peak acc\n(m/s²)", ".1f"),
    *SMOOTHNESS_COLUMNS[4:],
    ("angular_acceleration_peak_max", "peak ang acc\n(rad/s²)", ".1f"),
    ("angular_velocity_jump_max", "ang vel jump\nmax (rad/s)", ".3f"),
)

#: Per-goal table of a single pair: (row key, full title, compact title, format).
GOAL_TABLE_COLUMNS: tuple[tuple[str, str, str, str], ...] = (
    ("body", "body", "body", "d"),
    ("goal", "goal", "goal", "d"),
    ("time", "time", "time", ".3f"),
    ("position_error", "position_error", "pos err", ".2e"),
    ("orientation_error", "orientation_error", "ori err", ".2e"),
    ("closest_approach_offset", "closest_approach_offset", "closest", "+.3f"),
    ("entry_offset", "entry_offset", "entry", "+.3f"),
    ("success", "success", "ok", "s"),
)


def _table(title: str, wide: bool) -> Any:
    from rich import box
    from rich.table import Table

    if wide:
        return Table(title=title, box=box.SQUARE)
    return Table(title=title, box=box.SIMPLE_HEAD, pad_edge=False, collapse_padding=True)


def scorecard_table(
    summaries: Sequence[Mapping[str, Any]],
    title: str,
    wide: bool = False,
    columns: Sequence[tuple[str, str, str]] | None = None,
) -> Any:
    """A Rich table of scorecards, one row each (``columns``: by default compact or wide)."""
    from baselines.evaluation.scorecards import SCORECARD_COLUMNS, format_cell

    table = _table(title, wide)
    if columns is None:
        columns = SCORECARD_COLUMNS if wide else COMPACT_COLUMNS
    for _, name, fmt in columns:
        text = fmt == "s"
        table.add_column(name, justify="left" if text else "right", overflow="fold")
    for s in summaries:
        table.add_row(*(format_cell(s.get(k), f) for k, _, f in columns))
    return table


def goal_table(rows: Sequence[Mapping[str, Any]], wide: bool = False, limit: int = 40) -> Any:
    """The first episode's goals of one pair, one row each."""
    from baselines.evaluation.scorecards import format_cell

    table = _table("episode 0, per goal", wide)
    for _, full, short, _ in GOAL_TABLE_COLUMNS:
        table.add_column(full if wide else short, justify="right")
    for row in [r for r in rows if r["episode"] == 0][:limit]:
        table.add_row(*(format_cell(row[key], fmt) for key, _, _, fmt in GOAL_TABLE_COLUMNS))
    return table


def goals_met_line(summaries: Sequence[Mapping[str, Any]]) -> str:
    """Goals met per policy, summed over the envs: the comparison in one line."""
    met: dict[str, list[int]] = {}
    for s in summaries:
        counts = met.setdefault(str(s["policy"]), [0, 0])
        counts[0] += int(s.get("goals_met", 0))
        counts[1] += int(s.get("n_goals", 0))
    return "goals met: " + ", ".join(f"{p} {m}/{n}" for p, (m, n) in met.items())


class RunProgress:
    """A progress bar over a benchmark's runs (a line per outcome in a pipe); its methods are
    :func:`baselines.benchmark.driver.run_grid`'s callbacks."""

    def __init__(self, console: Any, total: int) -> None:
        from rich.progress import (
            BarColumn,
            MofNCompleteColumn,
            Progress,
            TextColumn,
            TimeElapsedColumn,
        )

        self.console = console
        self.counts = {"running": 0, "done": 0, "failed": 0}
        columns = (TextColumn("[bold]runs"), BarColumn(), MofNCompleteColumn(),
                   TextColumn("{task.description}"), TimeElapsedColumn())  # fmt: skip
        self.progress = Progress(*columns, console=console, disable=not console.is_terminal)
        self.task = self.progress.add_task(self._status(), total=total)

    def __enter__(self) -> RunProgress:
        self.progress.__enter__()
        return self

    def __exit__(self, *exc: Any) -> None:
        self.progress.__exit__(*exc)

    def _status(self) -> str:
        c = self.counts
        return f"done {c['done']}, running {c['running']}, failed {c['failed']}"

    def started(self, run_id: str) -> None:
        self.counts["running"] += 1
        self.progress.update(self.task, description=self._status())

    def finished(self, outcome: Mapping[str, Any], folder: Any) -> None:
        ok = outcome["status"] == "finished"
        self.counts["running"] -= 1
        self.counts["done" if ok else "failed"] += 1
        line = f"{outcome['run_id']}: {'finished' if ok else 'FAILED'} in "
        line += f"{outcome['wall_time_s']:.0f} s"
        if not ok:
            line += f" ({outcome['error']}; see {folder}/failed.json)"
        if self.console.is_terminal:
            self.progress.console.print(line)
        else:
            print(line, flush=True)
        self.progress.update(self.task, advance=1, description=self._status())

    def elsewhere(self, run_id: str) -> None:
        self.progress.update(self.task, advance=1)


def demo_scorecard_table(option: Any, result: Any) -> Any:
    """The per-rod scorecard of one run of ``sgc demo``, as a rich table."""
    from rich.table import Table

    if option.policy == "expert":
        rule = "the paper's k rules" if option.end_rule == "paper" else "the tangent rule"
        who = f"the expert ({rule})"
    else:
        who = f"policy {result.label}"
    table = Table(title=f"three-rod demo: {who}, scored by the harness")
    table.add_column("rod", no_wrap=True)
    for column in ("goals", "met", "max |D| (m)", "max |phi| (rad)", "closest approach (s)",
                   "SPARC", "min speed at goals / avg", "kink (m/s²)",
                   "ang kink (rad/s²)"):  # fmt: skip
        table.add_column(column, justify="right")
    for rod in result.per_rod:
        table.add_row(
            rod["rod"], str(rod["goals"]), str(rod["goals_met"]),
            _fmt(rod["position_error_max_m"]), _fmt(rod["orientation_error_max_rad"]),
            _fmt(rod["closest_approach_offset_max_s"]), _fmt(rod["sparc_track"], ".2f"),
            _fmt(rod["goal_speed_ratio_min"], ".2f"), _fmt(rod["acceleration_kink"], ".1f"),
            _fmt(rod["angular_acceleration_kink"], ".1f"),
        )  # fmt: skip
    return table


def _fmt(value: float | None, spec: str = ".1e") -> str:
    return "-" if value is None else format(value, spec)


def print_training(result: Any, cfg: Any, out: Any) -> None:
    """What ``sgc train`` did: steps, times, cloning, the model file and the last evaluation
    (``result``: a :class:`~baselines.agents.train.TrainResult` of ``cfg``; ``out``: its folder)."""
    if cfg.time_budget_s is not None:
        spent = "spent" if result.config["budget_spent"] else "not spent"
        print(f"time budget {cfg.time_budget_s:g} s {spent}: {result.timesteps} steps reached "
              f"in {result.config['train_time_s']:.1f} s of training")  # fmt: skip
    print(
        f"{cfg.algo} on {cfg.env_id}: {result.timesteps} steps, learn {result.learn_time_s:.1f} s "
        f"({result.steps_per_s:.0f} steps/s), total {result.wall_time_s:.1f} s"
    )
    if result.bc:
        print(f"bc: loss {result.bc['loss_before']:.4g} -> {result.bc['loss_after']:.4g}")
    if result.model_path is not None:
        print(f"model: {result.model_path}")
    if result.evaluations:
        last = result.evaluations[-1]
        where = f"; every entry in {out}/evaluations.json" if out else ""
        print(
            f"evaluation at {last['timesteps']} steps ({cfg.eval_episodes} episodes from seed "
            f"{cfg.eval_seed}{where}):\n{summary_line(last)}"
        )
    else:
        print("not evaluated (add --eval-freq N or --eval-every-s S to score the model with the "
              "harness)")  # fmt: skip

def smoothness_line(card: dict[str, Any]) -> str:
    """The episode's smoothness, linear and angular: LDLJ over the track (mean over bodies),
    peak acceleration and the largest one-tick change of acceleration (the largest over
    bodies; docs/metrics.md)."""
    parts = []
    for prefix, unit, name in (("", "m/s²", "linear"), ("angular_", "rad/s²", "angular")):
        values = [card[f"{prefix}{k}"] for k in
                  ("ldlj_track_mean", "acceleration_peak", "acceleration_kink")]  # fmt: skip
        if all(isinstance(v, float) and math.isnan(v) for v in values):
            continue
        parts.append(
            f"{name}: LDLJ track {values[0]:.2f}, peak acceleration {values[1]:.3g} {unit}, "
            f"largest one-tick change of acceleration {values[2]:.3g} {unit}"
        )
    return "; ".join(parts) if parts else "no movement to score for smoothness"
