"""Per-seed table of `sgc train --out` runs: held-out goals met, steps, wall clock.

Why: issue 21 asks, per seed, for the goals met on held-out episodes, the steps and the
wall clock of the run; `config.json` has the last two, the harness gives the first::

    python scripts/seed_table.py runs/fast/rod/seed* [--episodes 50] [--seed 20000] \
        [--json runs/fast/rod/seeds.json]

Each run's ``final_model.zip`` is scored with :func:`held_out_result` (reset seeds
``seed`` .. ``seed + episodes - 1``, none of which training sees). ``--scored`` reads that
score from the ``result.json`` of a ``sgc benchmark`` run instead (it scored the final model
on the same kind of seeds), so a table of a running sweep costs no CPU beside it; a run
scored on other seeds or episodes is a ``ValueError``.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

from baselines.zoo.manifest import held_out_result, steps_trained


def _benchmark_score(run: Path, episodes: int, seed: int) -> dict[str, Any]:
    """The final model's held-out score a `sgc benchmark` run recorded, if it is the one asked."""
    path = run / "result.json"
    if not path.is_file():
        raise ValueError(f"{run}: --scored needs a `sgc benchmark` run with result.json")
    outcome = json.loads(path.read_text())
    spec = outcome["spec"]
    if (spec["eval_episodes"], spec["test_seed"]) != (episodes, seed):
        raise ValueError(f"{run}: result.json scored {spec['eval_episodes']} episodes from seed "
                         f"{spec['test_seed']}, not {episodes} from {seed}")  # fmt: skip
    return dict(outcome["scores"]["final"])


def seed_row(run: Path, episodes: int, seed: int, scored: bool = False) -> dict[str, Any]:
    """One run's figures; ``ValueError`` naming the folder when it is not a finished run."""
    config_path = run / "config.json"
    model = run / "final_model.zip"
    if not config_path.is_file() or not model.is_file():
        raise ValueError(f"{run}: no config.json or final_model.zip (not a finished run)")
    config = json.loads(config_path.read_text())
    env_kwargs = config.get("train_config", {}).get("env_kwargs") or None
    if scored:
        result = _benchmark_score(run, episodes, seed)
    else:
        result = held_out_result(model, config["env_id"], episodes, seed, env_kwargs)
    return {
        "run": str(run), "env_id": config["env_id"], "seed": config["seed"],
        "steps": steps_trained(config), "wall_time_s": round(config["wall_time_s"], 1),
        "learn_time_s": round(config["learn_time_s"], 1),
        "goals_met": result["goals_met"], "n_goals": result["n_goals"],
        "success_rate": result["success_rate"], "result": result,
    }  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("runs", nargs="+", type=Path, help="`sgc train --out` folders")
    parser.add_argument("--episodes", type=int, default=50, help="held-out episodes per run")
    parser.add_argument("--seed", type=int, default=20_000, help="first held-out reset seed")
    parser.add_argument("--json", type=Path, help="also write the rows here")
    parser.add_argument("--scored", action="store_true",
                        help="final score from a `sgc benchmark` run's result.json")
    args = parser.parse_args()
    rows = [seed_row(run, args.episodes, args.seed, args.scored) for run in args.runs]
    print("| env | seed | steps | wall (s) | learn (s) | goals met | rate |")
    print("|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['env_id']} | {r['seed']} | {r['steps']:,} | {r['wall_time_s']:.0f} | "
              f"{r['learn_time_s']:.0f} | {r['goals_met']:.0f}/{r['n_goals']:.0f} | "
              f"{r['success_rate']:.2f} |")  # fmt: skip
    learned = sum(r["success_rate"] >= 0.8 for r in rows)
    print(f"\n{learned}/{len(rows)} runs meet >= 80% of held-out goals")
    if args.json:
        args.json.write_text(json.dumps(rows, indent=1) + "\n")


if __name__ == "__main__":
    main()
