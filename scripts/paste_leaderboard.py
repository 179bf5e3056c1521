"""Paste a ``sgc benchmark`` leaderboard into a markdown document, between markers.

docs/results.md carries the leaderboards that ``sgc benchmark`` wrote, verbatim (its title
dropped and its env headings demoted to ``###``), each between the lines
``<!-- NAME:begin -->`` and ``<!-- NAME:end -->`` of its marker, so a rerun of the benchmark
updates it with one command::

    python scripts/paste_leaderboard.py --marker stock-leaderboard \
        runs/benchmark/budget/leaderboard.md docs/results.md

docs/results.md has two: ``stock-leaderboard`` (the equal wall-clock rows,
``scripts/run_budget_rows.sh``) and ``threerod-leaderboard`` (``scripts/run_threerod_rows.sh``).
Without ``--marker`` the pair is ``leaderboard``.
"""

from __future__ import annotations

import argparse
from pathlib import Path

DEFAULT_MARKER = "leaderboard"


def markers(name: str) -> tuple[str, str]:
    """The begin and end lines of the marker pair called ``name``."""
    return f"<!-- {name}:begin -->", f"<!-- {name}:end -->"


def leaderboard_body(text: str) -> str:
    """The leaderboard without its ``#`` title, env headings as ``###``."""
    lines = text.strip().splitlines()
    if not lines or not lines[0].startswith("# "):
        raise ValueError("not a leaderboard.md of `sgc benchmark` (no '# ' title line)")
    body = [("#" + line) if line.startswith("## ") else line for line in lines[1:]]
    return "\n".join(body).strip()


def paste(document: str, body: str, where: str, marker: str = DEFAULT_MARKER) -> str:
    begin, end = markers(marker)
    if document.count(begin) != 1 or document.count(end) != 1:
        raise ValueError(f"{where}: needs exactly one {begin} and one {end} line")
    head, rest = document.split(begin)
    _, tail = rest.split(end)
    return f"{head}{begin}\n{body}\n{end}{tail}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("leaderboard", type=Path, help="leaderboard.md written by sgc benchmark")
    parser.add_argument("documents", type=Path, nargs="+", help="markdown files with the markers")
    parser.add_argument(
        "--marker", default=DEFAULT_MARKER,
        help="paste between <!-- MARKER:begin --> and <!-- MARKER:end -->",
    )  # fmt: skip
    args = parser.parse_args()
    body = leaderboard_body(args.leaderboard.read_text())
    for doc in args.documents:
        try:
            doc.write_text(paste(doc.read_text(), body, str(doc), args.marker))
        except ValueError as exc:
            parser.error(str(exc))
        print(f"pasted {args.leaderboard} into {doc}")


if __name__ == "__main__":
    main()
