"""``sgc demos``: record seeded expert episodes to an npz file (format in docs/agents.md)."""

from __future__ import annotations

import argparse
import json


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--env", required=True, help="registered id with a flat observation")
    parser.add_argument("--episodes", type=int, required=True)
    parser.add_argument("--seed", type=int, default=0, help="episodes use seed, seed+1, ...")
    parser.add_argument("--out", required=True, help="output .npz")
    parser.add_argument("--env-kwargs", default=None, help="JSON dict passed to gym.make")


def run(args: argparse.Namespace) -> int:
    from baselines.agents.demos import record_demos

    env_kwargs = json.loads(args.env_kwargs) if args.env_kwargs else {}
    if not isinstance(env_kwargs, dict):
        raise ValueError(f"--env-kwargs must be a JSON object, got {args.env_kwargs!r}")
    demos = record_demos(args.env, args.episodes, args.seed, env_kwargs)
    path = demos.save(args.out)
    print(f"{demos.n_episodes} episodes, {len(demos)} steps of {args.env} -> {path}")
    return 0
