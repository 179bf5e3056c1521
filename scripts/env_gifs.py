"""Write the expert's GIF of every env card into docs/images/ (``expert_<id>.gif``).

Usage: PYTHONPATH=$PWD .venv/bin/python scripts/env_gifs.py [--ids SGCRod-v1 ...] [--seed 0]

240x180 at 8 fps, seed 0 (the same scene the card describes for a fixed id; the first drawn
scene for a random one). Prints each file's size: keep them at a few hundred KB.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import sgc_env  # noqa: F401  (registers the ids)
from baselines.figures.episode_gif import episode_gif
from sgc_env.env_cards import CARDS, gif_path

DOCS = Path(__file__).resolve().parents[1] / "docs"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    own = [card.gif_id for card in CARDS if card.gif_of is None]
    parser.add_argument("--ids", nargs="*", default=own)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--fps", type=float, default=8.0)
    args = parser.parse_args()
    for env_id in args.ids:
        path = episode_gif(env_id, "expert", DOCS / gif_path(env_id), seed=args.seed,
                           fps=args.fps)  # fmt: skip
        print(f"{path.relative_to(DOCS.parent)}: {path.stat().st_size / 1024:.0f} KB")


if __name__ == "__main__":
    main()
