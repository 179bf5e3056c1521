"""``sgc paste``: a leaderboard of ``sgc benchmark`` into markdown documents, between markers.

The documents keep their leaderboards between ``<!-- NAME:begin -->`` and ``<!-- NAME:end -->``
(:mod:`baselines.benchmark.paste`); ``--merge`` updates a pasted leaderboard with a run of
some of its recipes, as the union of both runs would have written it.
"""

from __future__ import annotations

import argparse

from baselines.cli.checks import UsageError, existing_file

__all__ = ["add_arguments", "run"]


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("leaderboard", type=existing_file,
                        help="the leaderboard.md that sgc benchmark wrote")  # fmt: skip
    parser.add_argument("documents", type=existing_file, nargs="+",
                        help="markdown files holding the marker pair")  # fmt: skip
    parser.add_argument(
        "--marker", default="leaderboard",
        help="paste between <!-- MARKER:begin --> and <!-- MARKER:end -->",
    )  # fmt: skip
    parser.add_argument(
        "--merge", action="store_true",
        help="keep the pasted rows of recipes this leaderboard does not have",
    )  # fmt: skip


def run(args: argparse.Namespace) -> int:
    from baselines.benchmark.paste import block, leaderboard_body, merge, replace

    try:
        body = leaderboard_body(args.leaderboard.read_text(), str(args.leaderboard))
        updated = {}
        for doc in args.documents:
            text = doc.read_text()
            pasted = block(text, args.marker, str(doc))
            new = merge(pasted, body, str(doc)) if args.merge else body
            updated[doc] = replace(text, args.marker, new, str(doc))
    except ValueError as exc:  # every document is checked before any is written
        raise UsageError(str(exc)) from None
    for doc, text in updated.items():
        doc.write_text(text)
        print(f"pasted {args.leaderboard} into {doc}")
    return 0
