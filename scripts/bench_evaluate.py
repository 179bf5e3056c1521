"""Wall clock of the harness on single envs vs the batched env, measured in one run.

``evaluate(..., num_envs=1)`` runs the episodes one after another on one env;
``num_envs=N`` runs them N at a time in one PyBullet world (``baselines.evaluation.episodes``).
Prints the median of ``--rounds`` runs of each and their ratio. A model file warms up (imports,
load) before timing.

    PYTHONPATH=$PWD .venv/bin/python scripts/bench_evaluate.py --env SGCPoint-v1 \\
        --policy expert baselines/checkpoints/ppo_dagger_SGCPoint-v1.zip --episodes 8
"""

from __future__ import annotations

import argparse
import statistics
import time

from baselines.evaluation.harness import evaluate


def _timed(policy: str, env_id: str, episodes: int, num_envs: int) -> float:
    started = time.perf_counter()
    evaluate(policy, env_id, episodes, seed=20000, keep_infos=0, num_envs=num_envs)
    return time.perf_counter() - started


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--env", default="SGCRod-v1")
    parser.add_argument("--policy", nargs="+", default=["expert"])
    parser.add_argument("--episodes", type=int, default=8)
    parser.add_argument("--num-envs", type=int, default=8)
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args()
    print(f"{'policy':42} {'single s':>9} {'batched s':>9} {'x single':>8}")
    for policy in args.policy:
        evaluate(policy, args.env, 1, seed=0, keep_infos=0)  # warm-up: imports, model load
        single, batched = [], []
        for _ in range(args.rounds):  # interleaved, so load changes hit both alike
            single.append(_timed(policy, args.env, args.episodes, 1))
            batched.append(_timed(policy, args.env, args.episodes, args.num_envs))
        a, b = statistics.median(single), statistics.median(batched)
        print(f"{policy[-42:]:42} {a:9.2f} {b:9.2f} {a / b:8.2f}")


if __name__ == "__main__":
    main()
