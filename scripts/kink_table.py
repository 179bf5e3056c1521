"""Per-rod kinks of the expert against minimum jerk: the table of docs/smoothness.md.

The kink is the largest one-tick change of acceleration over a body's whole track
(docs/metrics.md), linear (the tracked point) and angular. For every rod of the paper's
three-rod scene (``SGCThreeRods-v2``) and of held-out random rod scenes
(``SGCThreeRodsRandom-v3``, seeds from 10000) it prints the expert's kinks, minimum jerk's and
their ratio; the issue asks for a ratio of at most 2 everywhere. Exit status 1 when a ratio
exceeds ``--limit``.

    PYTHONPATH=$PWD .venv/bin/python scripts/kink_table.py --episodes 5
"""

from __future__ import annotations

import argparse
import sys
from typing import Any

from baselines.evaluation.harness import evaluate
from sgc_env.defaults import EVAL_SEED

FIGURES = ("acceleration_kink", "angular_acceleration_kink")


def rod_rows(policy: str, env_id: str, episodes: int, seed: int) -> list[dict[str, Any]]:
    """One row per rod and episode: its kinks and whether every goal was met."""
    result = evaluate(policy, env_id, episodes, seed, keep_infos=0)
    rows = []
    for record in result.episodes:
        for body, card in enumerate(record.card["bodies"]):
            if card is None:
                continue
            row = {"episode": record.episode, "body": body, "met": card["goals_met"],
                   "goals": card["n_goals"]}  # fmt: skip
            row.update({key: card[key] for key in FIGURES})
            rows.append(row)
    return rows


def compare(env_id: str, episodes: int, seed: int, policy: str) -> list[dict[str, Any]]:
    """The expert's rows with minimum jerk's kinks and the ratios beside them."""
    expert = rod_rows(policy, env_id, episodes, seed)
    reference = rod_rows("minimum-jerk", env_id, episodes, seed)
    out = []
    for mine, ref in zip(expert, reference, strict=True):
        row = {"env": env_id, **mine}
        for key in FIGURES:
            row[f"{key}_mj"] = ref[key]
            row[f"{key}_ratio"] = mine[key] / ref[key]
        out.append(row)
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--episodes", type=int, default=5, help="random scenes (default 5)")
    parser.add_argument("--seed", type=int, default=EVAL_SEED)
    parser.add_argument(
        "--policy", default="expert",
        help="expert, expert-paper, expert-matched or expert-smooth",
    )  # fmt: skip
    parser.add_argument("--limit", type=float, default=2.0, help="largest ratio that passes")
    args = parser.parse_args(argv)
    rows = compare("SGCThreeRods-v2", 1, 0, args.policy)
    rows += compare("SGCThreeRodsRandom-v3", args.episodes, args.seed, args.policy)
    print(f"| env | episode | rod | goals met | {args.policy} kink (m/s²) | minimum jerk | ratio "
          f"| {args.policy} angular kink (rad/s²) | minimum jerk | ratio |")  # fmt: skip
    print("|---|---|---|---|---|---|---|---|---|---|")
    worst = 0.0
    for r in rows:
        lin, ang = "acceleration_kink", "angular_acceleration_kink"
        print(
            f"| {r['env']} | {r['episode']} | {r['body']} | {r['met']}/{r['goals']} "
            f"| {r[lin]:.2f} | {r[lin + '_mj']:.2f} | {r[lin + '_ratio']:.2f} "
            f"| {r[ang]:.2f} | {r[ang + '_mj']:.2f} | {r[ang + '_ratio']:.2f} |"
        )
        worst = max(worst, r[lin + "_ratio"], r[ang + "_ratio"])
    print(f"largest ratio: {worst:.2f} (limit {args.limit})")
    return 0 if worst <= args.limit else 1


if __name__ == "__main__":
    sys.exit(main())
