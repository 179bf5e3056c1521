"""``sgc card``: write the model card of shipped models (``baselines/checkpoints/<stem>.md``).

Each card's held-out results come from an evaluation this command runs (``--episodes`` from
``--seed``, default the seed the manifest's result started at), next to the results the
manifest recorded when the model was shipped; see :mod:`baselines.zoo.cards`.
"""

from __future__ import annotations

import argparse

from baselines.cli.checks import UsageError, nonneg_int, positive_int

__all__ = ["add_arguments", "run"]


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("models", nargs="*", metavar="STEM",
                        help="shipped model file stems (default: every shipped model)")  # fmt: skip
    parser.add_argument("--episodes", type=positive_int, default=10,
                        help="held-out episodes the card evaluates")  # fmt: skip
    parser.add_argument("--seed", type=nonneg_int, default=None,
                        help="first held-out seed (default: the manifest result's)")  # fmt: skip
    parser.add_argument("--no-gif", action="store_true",
                        help="keep the episode GIF there is (no new episode drawn)")  # fmt: skip


def run(args: argparse.Namespace) -> int:
    from baselines.zoo.cards import entries, write_model_card

    try:
        chosen = entries(args.models)
    except ValueError as exc:
        raise UsageError(str(exc)) from None
    for entry in chosen:
        path = write_model_card(entry, episodes=args.episodes, seed=args.seed,
                                gif=not args.no_gif)  # fmt: skip
        print(path)
    return 0
