"""``sgc convert``: trusted model files (SB3's or rl-zoo3's ``vecnormalize.pkl``, model
``.zip``) into the formats every other command loads without unpickling
(:mod:`baselines.models.convert`). It unpickles, so it runs only with ``--trust-model``."""

from __future__ import annotations

import argparse
from pathlib import Path

from baselines.cli.checks import UsageError, add_trust_argument, trust_model

__all__ = ["add_arguments", "run"]


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("paths", nargs="+", type=Path, metavar="PATH",
                        help="a vecnormalize .pkl, a model .zip, or a folder of them")  # fmt: skip
    add_trust_argument(parser)


def run(args: argparse.Namespace) -> int:
    from baselines.models.convert import convert_files

    if not args.trust_model:
        raise UsageError("converting unpickles the files, which can run code: pass "
                         "--trust-model, only for files you made or trust")  # fmt: skip
    trust_model(args, "convert")
    try:
        lines = convert_files(args.paths)
    except ValueError as exc:
        raise UsageError(str(exc)) from None
    print("\n".join(lines) if lines else "nothing to convert")
    return 0
