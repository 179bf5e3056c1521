"""Write ``constraints.txt``: the tested version of every package the set-up installs.

Walks the requirement closure of ``sgc[<extras>]`` through the installed distributions of the
running interpreter (the working ``.venv``), so the file holds exactly what ``scripts/setup.sh``
would pull, at the versions the test suite last passed with, and nothing that merely happens to
sit in the same venv. ``pyproject.toml`` keeps ranges for people installing into their own
environment; the set-up script passes this file to pip with ``-c``.

    .venv/bin/python scripts/freeze_constraints.py            # rewrite constraints.txt
    .venv/bin/python scripts/freeze_constraints.py --check    # exit 1 if it is stale
"""

from __future__ import annotations

import argparse
import sys
from importlib import metadata
from pathlib import Path

import tomllib
from packaging.requirements import Requirement
from packaging.utils import canonicalize_name

ROOT = Path(__file__).resolve().parents[1]
EXTRAS = ("rl", "ray", "dev", "minari", "docs")
HEADER = (
    "# Tested versions: written by scripts/freeze_constraints.py from the working venv\n"
    "# (Python {python}). scripts/setup.sh installs with `pip install -c constraints.txt`.\n"
)


def _roots(extras: tuple[str, ...]) -> list[Requirement]:
    """The project's own requirements, read from ``pyproject.toml`` (not a stale install)."""
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    texts = list(project["dependencies"])
    for extra in extras:
        texts += project["optional-dependencies"][extra]
    return [Requirement(t) for t in texts]


def closure(extras: tuple[str, ...]) -> dict[str, str]:
    """Canonical name -> installed version of every distribution ``sgc[extras]`` needs."""
    found: dict[str, str] = {}
    stack = [(r.name, frozenset(r.extras)) for r in _roots(extras)]
    seen: set[tuple[str, frozenset[str]]] = set()
    while stack:
        name, wanted = stack.pop()
        if (name, wanted) in seen:
            continue
        seen.add((name, wanted))
        dist = metadata.distribution(name)
        found[canonicalize_name(name)] = dist.version
        for text in dist.requires or []:
            req = Requirement(text)
            envs = [{"extra": e} for e in wanted] or [{"extra": ""}]
            if req.marker is not None and not any(req.marker.evaluate(env) for env in envs):
                continue
            try:
                metadata.distribution(req.name)
            except metadata.PackageNotFoundError:
                continue  # an optional requirement for another platform or Python
            stack.append((req.name, frozenset(req.extras)))
    return found


def render(pins: dict[str, str]) -> str:
    python = ".".join(map(str, sys.version_info[:3]))
    body = "".join(f"{name}=={pins[name]}\n" for name in sorted(pins))
    return HEADER.format(python=python) + body


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="fail if constraints.txt differs")
    args = parser.parse_args()
    text = render(closure(EXTRAS))
    path = ROOT / "constraints.txt"
    if args.check:
        stale = not path.is_file() or path.read_text() != text
        print(f"{path}: {'stale' if stale else 'up to date'}")
        return int(stale)
    path.write_text(text)
    print(f"wrote {path} ({text.count(chr(10)) - 2} pins)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
