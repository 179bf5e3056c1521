"""The ``sgc`` console command: one subcommand per module in :mod:`baselines.cli.commands`.

Each command module exposes ``add_arguments(parser)`` and ``run(args) -> int``; heavy imports
(PyBullet, torch) happen inside ``run`` so that ``sgc --help`` stays fast.
"""

from __future__ import annotations

import argparse
import importlib
import sys
from collections.abc import Sequence

from baselines.cli.checks import UsageError, error_exit
from baselines.cli.console import DefaultsHelpFormatter

__all__ = ["COMMANDS", "build_parser", "main"]

COMMANDS: dict[str, str] = {
    "demo": "the paper's three-rod demo: video, plates, plots and scorecard",
    "train": "train an SB3 agent (PPO, SAC, TD3, SAC+HER) with harness evaluation",
    "demos": "record seeded expert demonstrations to an npz file",
    "evaluate": "score policies on envs with the shared harness: tables, CSV, JSON, plots",
    "rollout": "one scenario, one controller: trajectory npz, deviation/path/speed plots, video",
    "benchmark": "train recipes x envs x seeds (local pool or Ray); leaderboard with IQM and CIs",
    "card": "write the model cards of shipped models, with a fresh held-out evaluation",
    "convert": "trusted SB3 / rl-zoo3 statistics (.pkl) and models into files loaded unpickled",
    "bench": "how fast the envs run here: against a bare PyBullet loop, or another checkout",
    "paste": "paste a leaderboard of sgc benchmark into markdown documents, between markers",
}


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="sgc", description="Sequential-goal constraints: environments, expert, benchmark."
    )
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for name, help_text in COMMANDS.items():
        module = importlib.import_module(f"baselines.cli.commands.{name.replace('-', '_')}")
        command_parser = sub.add_parser(
            name, help=help_text, description=help_text, formatter_class=DefaultsHelpFormatter
        )
        module.add_arguments(command_parser)
        command_parser.set_defaults(_module=module)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    words = list(sys.argv[1:] if argv is None else argv)
    try:
        args = build_parser().parse_args(words)
    except SystemExit as exc:  # argparse: --help (0), or a bad argument reported in one line (2)
        return int(exc.code or 0)
    args.argv = words  # for commands that record how they were called
    try:
        return int(args._module.run(args) or 0)
    except UsageError as exc:  # a bad argument found before any work; real bugs still raise
        return error_exit(args.command, exc)


if __name__ == "__main__":
    raise SystemExit(main())
