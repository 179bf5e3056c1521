"""``sgc demos``: record seeded expert episodes to an npz file or a Minari dataset.

Formats in docs/agents.md; ``--format minari`` needs the ``minari`` extra and writes dataset
``--out`` (an id such as ``sgc/point/expert-v0``) under Minari's datasets folder.
"""

from __future__ import annotations

import argparse
import json
import sys
from typing import Any


def add_push_arguments(parser: argparse.ArgumentParser) -> None:
    """``--push-*``: random impulses for state diversity (shared with ``sgc train``)."""
    parser.add_argument(
        "--push-scale", type=float, default=0.0,
        help="per-axis std (m/s) of a push's velocity change (0: no pushes)",
    )  # fmt: skip
    parser.add_argument(
        "--push-spin", type=float, default=0.0,
        help="per-axis std (rad/s) of a push's angular velocity change (bodies with torques)",
    )  # fmt: skip
    parser.add_argument("--push-prob", type=float, default=0.05, help="chance of a push per tick")
    parser.add_argument("--push-start", action="store_true", help="push every episode at tick 0")


def push_options(args: argparse.Namespace) -> dict[str, Any]:
    """The ``--push-*`` values under the keyword names of ``Pushes`` / ``TrainConfig``."""
    return {
        "scale": args.push_scale, "spin": args.push_spin,
        "prob": args.push_prob, "start": args.push_start,
    }  # fmt: skip


def parse_env_kwargs(text: str | None) -> dict[str, Any]:
    """``--env-kwargs`` as a dict (a JSON object or nothing)."""
    env_kwargs = json.loads(text) if text else {}
    if not isinstance(env_kwargs, dict):
        raise ValueError(f"--env-kwargs must be a JSON object, got {text!r}")
    return env_kwargs


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--env", required=True, help="registered id with a flat observation")
    parser.add_argument("--episodes", type=int, required=True, help="how many episodes")
    parser.add_argument("--seed", type=int, default=0, help="episodes use seed, seed+1, ...")
    parser.add_argument("--out", required=True, help="output .npz, or the Minari dataset id")
    parser.add_argument(
        "--format", choices=("npz", "minari"), default="npz",
        help="npz: flat arrays (docs/agents.md); minari: a Minari dataset (extra 'minari')",
    )  # fmt: skip
    parser.add_argument("--env-kwargs", default=None, help="JSON dict passed to gym.make")
    add_push_arguments(parser)


def _run_minari(args: argparse.Namespace, env_kwargs: dict[str, Any]) -> int:
    try:
        from baselines.agents.minari_data import record_minari
    except ImportError as exc:
        print(
            f"sgc demos: error: --format minari needs the minari extra ({exc}); "
            "install it with: .venv/bin/pip install -e '.[minari]'",
            file=sys.stderr,
        )
        return 2
    if args.push_scale or args.push_spin or args.push_start:
        print("sgc demos: error: --format minari records unpushed episodes only", file=sys.stderr)
        return 2
    dataset = record_minari(args.env, args.episodes, args.seed, args.out, env_kwargs)
    print(
        f"{dataset.total_episodes} episodes, {dataset.total_steps} steps of {args.env} -> "
        f"Minari dataset {args.out!r} ({dataset.spec.data_path})"
    )
    return 0


def run(args: argparse.Namespace) -> int:
    from baselines.agents.demos import record_demos
    from baselines.agents.pushes import Pushes

    env_kwargs = parse_env_kwargs(args.env_kwargs)
    if args.format == "minari":
        return _run_minari(args, env_kwargs)
    pushes = Pushes(**push_options(args))
    demos = record_demos(args.env, args.episodes, args.seed, env_kwargs, pushes=pushes)
    path = demos.save(args.out)
    print(f"{demos.n_episodes} episodes, {len(demos)} steps of {args.env} -> {path}")
    return 0
