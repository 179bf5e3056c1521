"""``sgc demo``: the paper's three-rod demo, run by the expert, rendered and scored.

Writes to ``--out`` (default ``runs/demo``): ``three_rods.mp4``, ``three_rods.gif``,
``plates.png`` (8 frames, like the paper's Plates 1-8), ``deviation.png`` and ``speed.png``
(per rod), ``goals.csv`` (one row per goal), ``summary.json`` (the harness's scorecard) and
``rods.json`` (exactness, punctuality and smoothness per rod). ``--paper-rule`` runs the
expert with the paper's k rules instead of the tangent rule. It prints the CPU time it took
(``os.times``: this process since it started, plus waited-for children such as ffmpeg), the
measure that matters on a shared machine, and the wall time.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from baselines.cli.checks import bounded_int, out_dir, staged_output

__all__ = ["add_arguments", "run"]


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--out", type=out_dir, default=Path("runs/demo"), help="output folder")
    parser.add_argument(
        "--width", type=bounded_int(16, 4096), default=960, help="video width in pixels"
    )
    parser.add_argument(
        "--height", type=bounded_int(16, 4096), default=540, help="video height in pixels"
    )
    parser.add_argument(
        "--no-video", action="store_true", help="skip rendering (scorecard and plots only)"
    )
    parser.add_argument(
        "--paper-rule", action="store_true",
        help="end interior courses by the paper's k rules (eqs. 12-14) instead of the tangent "
        "rule",
    )  # fmt: skip


def run(args: argparse.Namespace) -> int:
    import gymnasium as gym
    from rich.console import Console
    from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn
    from rich.table import Table

    import sgc_env  # noqa: F401  (registers the ids)
    from baselines.cli.demo import ENV_ID, DemoOptions, cpu_seconds, run_demo

    console = Console()
    started = time.perf_counter()
    # Written next to --out and moved in at the end: an interrupted run leaves the earlier
    # results whole (no half-written video beside old plates).
    with staged_output(args.out) as stage, Progress(
        TextColumn("three rods"), BarColumn(), TextColumn("{task.completed}/{task.total} ticks"),
        TimeRemainingColumn(), console=console,
    ) as bar:  # fmt: skip
        options = DemoOptions(
            out=stage, width=args.width, height=args.height, video=not args.no_video,
            end_rule="paper" if args.paper_rule else "tangent",
        )  # fmt: skip
        # the registry's episode length is the demo's tick count, known before the env is built
        task = bar.add_task("demo", total=gym.spec(ENV_ID).max_episode_steps)
        result = run_demo(options, lambda done, n: bar.update(task, completed=done, total=n))
        files = sorted(args.out / path.relative_to(stage) for path in result.files.values())
    elapsed = time.perf_counter() - started

    rule = "the paper's k rules" if args.paper_rule else "the tangent rule"
    table = Table(title=f"three-rod demo: the expert ({rule}), scored by the harness")
    table.add_column("rod", no_wrap=True)
    for column in ("goals", "met", "max |D| (m)", "max |phi| (rad)", "closest approach (s)",
                   "SPARC", "min speed at goals / avg", "kink (m/s²)",
                   "ang kink (rad/s²)"):  # fmt: skip
        table.add_column(column, justify="right")
    for rod in result.per_rod:
        table.add_row(
            rod["rod"], str(rod["goals"]), str(rod["goals_met"]),
            f"{rod['position_error_max_m']:.1e}", _fmt(rod["orientation_error_max_rad"]),
            _fmt(rod["closest_approach_offset_max_s"]), _fmt(rod["sparc_track"], ".2f"),
            _fmt(rod["goal_speed_ratio_min"], ".2f"), _fmt(rod["acceleration_kink"], ".1f"),
            _fmt(rod["angular_acceleration_kink"], ".1f"),
        )  # fmt: skip
    console.print(table)
    summary = result.summary
    console.print(
        f"{summary['goals_met']}/{summary['n_goals']} goals met, terminated: "
        f"{bool(summary['terminated'])}; CPU {cpu_seconds():.1f} s since the command started "
        f"(imports included, ffmpeg's too), of which the run {result.cpu_s:.1f} s; "
        f"{elapsed:.1f} s wall clock"
    )
    console.print(f"outputs in {args.out}/:")
    for path in files:
        console.print(f"  {path}")
    return 0 if summary["goals_met"] == summary["n_goals"] and not summary["terminated"] else 1


def _fmt(value: float | None, spec: str = ".1e") -> str:
    return "-" if value is None else format(value, spec)
