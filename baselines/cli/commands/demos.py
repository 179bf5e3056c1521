"""``sgc demos``: record seeded expert episodes to an npz file or a Minari dataset.

Formats in docs/agents.md; ``--format minari`` needs the ``minari`` extra and writes dataset
``--out`` (an id such as ``sgc/point/expert-v0``) under Minari's datasets folder.
"""

from __future__ import annotations

import argparse
from typing import Any

from baselines.cli.checks import (
    UsageError,
    env_kwargs,
    fraction,
    known_env_id,
    nonneg_float,
    nonneg_int,
    out_file,
    positive_int,
)


def add_push_arguments(parser: argparse.ArgumentParser) -> None:
    """``--push-*``: random impulses for state diversity (shared with ``sgc train``)."""
    parser.add_argument(
        "--push-scale", type=nonneg_float, default=0.0,
        help="per-axis std (m/s) of a push's velocity change (0: no pushes)",
    )  # fmt: skip
    parser.add_argument(
        "--push-spin", type=nonneg_float, default=0.0,
        help="per-axis std (rad/s) of a push's angular velocity change (bodies with torques)",
    )  # fmt: skip
    parser.add_argument(
        "--push-prob", type=fraction, default=0.05, help="chance of a push per tick"
    )
    parser.add_argument("--push-start", action="store_true", help="push every episode at tick 0")


def push_options(args: argparse.Namespace) -> dict[str, Any]:
    """The ``--push-*`` values under the keyword names of ``Pushes`` / ``TrainConfig``."""
    return {
        "scale": args.push_scale, "spin": args.push_spin,
        "prob": args.push_prob, "start": args.push_start,
    }  # fmt: skip


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--env", required=True, help="registered id with a flat observation")
    parser.add_argument("--episodes", type=positive_int, required=True, help="how many episodes")
    parser.add_argument(
        "--seed", type=nonneg_int, default=0, help="episodes use seed, seed+1, ..."
    )
    parser.add_argument("--out", required=True, help="output .npz, or the Minari dataset id")
    parser.add_argument(
        "--format", choices=("npz", "minari"), default="npz",
        help="npz: flat arrays (docs/agents.md); minari: a Minari dataset (extra 'minari')",
    )  # fmt: skip
    parser.add_argument(
        "--env-kwargs", type=env_kwargs, default=None, help="JSON dict passed to gym.make"
    )
    add_push_arguments(parser)


def _run_minari(args: argparse.Namespace) -> int:
    try:
        from baselines.agents.minari_data import check_dataset_id, record_minari
    except ImportError as exc:
        raise UsageError(
            f"--format minari needs the minari extra ({exc}); "
            "install it with: .venv/bin/pip install -e '.[minari]'"
        ) from None
    if args.push_scale or args.push_spin or args.push_start:
        raise UsageError("--format minari records unpushed episodes only")
    try:
        check_dataset_id(args.out)
    except ValueError as exc:
        raise UsageError(f"--out: {exc}") from None
    dataset = record_minari(args.env, args.episodes, args.seed, args.out, args.env_kwargs)
    print(
        f"{dataset.total_episodes} episodes, {dataset.total_steps} steps of {args.env} -> "
        f"Minari dataset {args.out!r} ({dataset.spec.data_path})"
    )
    return 0


def run(args: argparse.Namespace) -> int:
    from baselines.agents.demos import record_demos
    from baselines.agents.pushes import Pushes
    from baselines.common.env_kwargs import check_env_kwargs

    known_env_id(args.env)
    try:
        check_env_kwargs(args.env, args.env_kwargs, "--env-kwargs")
    except ValueError as exc:
        raise UsageError(str(exc)) from None
    if args.format == "minari":
        return _run_minari(args)
    try:
        out = out_file(args.out)
    except argparse.ArgumentTypeError as exc:
        raise UsageError(f"--out: {exc}") from None
    pushes = Pushes(**push_options(args))
    demos = record_demos(args.env, args.episodes, args.seed, args.env_kwargs or {}, pushes=pushes)
    path = demos.save(out)
    print(f"{demos.n_episodes} episodes, {len(demos)} steps of {args.env} -> {path}")
    return 0
