"""``sgc demo``: the paper's three-rod demo, flown by the expert or any policy, rendered and
scored (:mod:`baselines.figures.demo`: the outputs).

``--paper-rule`` runs the expert with the paper's k rules instead of the tangent rule;
``--policy SPEC`` flies any spec ``sgc evaluate --policy`` takes; ``--compare A,B`` runs both
and writes them side by side (:mod:`baselines.figures.demo_compare`). The exit status is 1 when
the expert (alone or compared) misses a goal, 2 for bad input (an unknown spec, a model that
does not fit the three-rod env), else 0. It prints the CPU time (``os.times``, ffmpeg's
included: the measure that matters on a shared machine) and the wall time.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path
from typing import Any

from baselines.cli.checks import (
    add_trust_argument,
    bounded_int,
    error_exit,
    out_dir,
    staged_output,
    trust_model,
)
from baselines.cli.console import make_console

__all__ = ["add_arguments", "run"]


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--out", type=out_dir, default=Path("runs/demo"), help="output folder")
    for side, default in (("width", 960), ("height", 540)):
        parser.add_argument(f"--{side}", type=bounded_int(16, 4096), default=default,
                            help=f"video {side} in pixels")  # fmt: skip
    parser.add_argument(
        "--no-video", action="store_true", help="skip rendering (scorecard and plots only)"
    )
    parser.add_argument("--no-gltf", action="store_true",
                        help="skip three_rods.glb (the flight as glTF, for Blender or a browser)")
    parser.add_argument(
        "--paper-rule", action="store_true",
        help="end interior courses by the paper's k rules (eqs. 12-14) instead of the tangent "
        "rule",
    )  # fmt: skip
    who = parser.add_mutually_exclusive_group()
    who.add_argument(
        "--policy", default="expert", metavar="SPEC",
        help="the policy that flies the demo: expert | expert-paper | expert-matched | "
        "expert-smooth | minimum-jerk | dynamic-constraints | random | shipped:<stem> | "
        "SB3 .zip (default expert)",
    )  # fmt: skip
    who.add_argument(
        "--compare", metavar="A,B", default=None,
        help="fly two policies (e.g. expert,minimum-jerk) and write them side by side in "
        "compare.mp4, with both scorecards and both flights in compare.glb",
    )  # fmt: skip
    add_trust_argument(parser)


def _specs(args: argparse.Namespace) -> list[str]:
    """The policies to fly, with ``--paper-rule`` applied to the expert."""
    specs = [args.policy] if args.compare is None else [s.strip() for s in args.compare.split(",")]
    if args.compare is not None and (len(specs) != 2 or not all(specs)):
        raise ValueError(f"--compare: expected two specs A,B, got {args.compare!r}")
    if args.compare is not None and args.no_video:
        raise ValueError("--compare: draws the two runs side by side; drop --no-video")
    if args.paper_rule and "expert" not in specs:
        raise ValueError("--paper-rule: applies to the expert; use --policy expert-paper")
    return specs


def _labels(args: argparse.Namespace, specs: list[str]) -> list[str]:
    """Output folder and summary key per policy: the expert flown with ``--paper-rule`` is
    labelled ``expert-paper`` (the spec that means it), so the outputs say which rule flew."""
    from baselines.policies import policy_labels

    return policy_labels(
        ["expert-paper" if args.paper_rule and spec == "expert" else spec for spec in specs]
    )


def run(args: argparse.Namespace) -> int:
    import sgc_env  # noqa: F401  (registers the ids)
    from baselines.figures.demo import DemoOptions, check_policy

    try:
        specs = _specs(args)
        labels = _labels(args, specs)
        trust = trust_model(args, "demo")
        options = [
            DemoOptions(
                out=args.out, width=args.width, height=args.height,
                video=not args.no_video, gltf=not args.no_gltf, policy=spec,
                end_rule="paper" if args.paper_rule and spec == "expert" else "tangent",
                trust_model=trust,
            )  # fmt: skip
            for spec in specs
        ]
        for option in options:  # a spec or model that does not fit fails here, on one line
            check_policy(option)
        return _fly(args, options, labels)
    except ValueError as exc:
        return error_exit("demo", exc)


def _fly(args: argparse.Namespace, options: list[Any], labels: list[str]) -> int:
    import gymnasium as gym
    from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn

    from baselines.cli.console import demo_scorecard_table
    from baselines.figures.demo import ENV_ID, cpu_seconds
    from baselines.figures.demo_compare import fly_demos

    console = make_console()
    started = time.perf_counter()
    # Written next to --out and moved in at the end: an interrupted run (or a model that does
    # not load) leaves the earlier results whole (no half-written video beside old plates).
    with staged_output(args.out) as stage, Progress(
        TextColumn("three rods: {task.description}"), BarColumn(),
        TextColumn("{task.completed}/{task.total} ticks"), TimeRemainingColumn(), console=console,
    ) as bar:  # fmt: skip

        def progress(label: str) -> Any:
            # the registry's episode length is the demo's tick count, known before the env is built
            task = bar.add_task(label, total=gym.spec(ENV_ID).max_episode_steps)
            return lambda done, total: bar.update(task, completed=done, total=total)

        results, written = fly_demos(options, labels, stage, progress)
        files = sorted(args.out / path.relative_to(stage) for path in written)
    elapsed = time.perf_counter() - started

    for option, result in zip(options, results, strict=True):
        console.print(demo_scorecard_table(option, result))
        summary = result.summary
        console.print(f"{result.label}: {summary['goals_met']}/{summary['n_goals']} goals met, "
                      f"terminated: {bool(summary['terminated'])}; CPU of the run "
                      f"{result.cpu_s:.1f} s")  # fmt: skip
    console.print(f"CPU {cpu_seconds():.1f} s since the command started (imports included, "
                  f"ffmpeg's too); {elapsed:.1f} s wall clock")  # fmt: skip
    console.print(f"outputs in {args.out}/:", *(f"  {path}" for path in files), sep="\n")
    missed = any(
        r.summary["goals_met"] < r.summary["n_goals"] or r.summary["terminated"]
        for o, r in zip(options, results, strict=True) if o.policy == "expert"
    )  # fmt: skip
    return 1 if missed else 0
