"""PPO training steps/s of hyperparameter folders (recipes) on one id, in one run.

Why: a recipe's wall clock is its steps over this rate, and the rate of a shared machine
moves with its load, so recipes are compared by their ratio to a reference timed in the same
run (the first ``--configs`` entry), each in a fresh child process, one after the other, with
``--repeats`` rounds keeping each configuration's best. Each child runs
:func:`baselines.agents.train.train` (the whole `sgc train` path, updates included) for
``--steps`` env steps, no evaluation::

    .venv/bin/python scripts/bench_recipes.py --env SGCRod-v1 --steps 32768 \
        --configs zoo:dummy zoo:batched

A FOLDER is relative to ``benchmarks/`` (``zoo``: rl-zoo3's files; ``hyperparams/NAME``).
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
from pathlib import Path

HYPERPARAMS = Path(__file__).resolve().parents[1] / "benchmarks"


def child(env_id: str, folder: str, vec: str, steps: int) -> dict[str, float]:
    """One timed training run (in its own process); learn-time steps/s."""
    from baselines.agents.train import TrainConfig, train

    cfg = TrainConfig("ppo", env_id, timesteps=steps, hyperparams_dir=HYPERPARAMS / folder, vec=vec)
    result = train(cfg)
    return {"steps": result.timesteps, "steps_s": result.steps_per_s}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--env", default="SGCRod-v1")
    parser.add_argument("--steps", type=int, default=32768, help="env steps per timed run")
    parser.add_argument("--configs", nargs="+",
                        default=["zoo:dummy", "zoo:batched"],
                        help="FOLDER:VEC; the first is the reference")  # fmt: skip
    parser.add_argument("--repeats", type=int, default=1)
    parser.add_argument("--child", nargs=3, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        folder, vec, env_id = args.child
        print(json.dumps(child(env_id, folder, vec, args.steps)))
        return
    for config in args.configs:
        folder, _, vec = config.partition(":")
        if not (HYPERPARAMS / folder / "ppo.yml").is_file() or vec not in ("batched", "dummy"):
            parser.error(f"--configs {config!r}: want FOLDER:batched|dummy with "
                         f"{HYPERPARAMS}/FOLDER/ppo.yml")  # fmt: skip
    best: dict[str, float] = {}
    for _ in range(args.repeats):
        for config in args.configs:
            folder, _, vec = config.partition(":")
            cmd = [sys.executable, __file__, "--steps", str(args.steps), "--child", folder, vec,
                   args.env]  # fmt: skip
            out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
            rate = json.loads(out.strip().splitlines()[-1])["steps_s"]
            best[config] = max(best.get(config, 0.0), rate)
    ref = best[args.configs[0]]
    print(f"{args.env}, {args.steps} steps per run, best of {args.repeats}")
    print(f"{'recipe:vec':<28} {'PPO steps/s':>11} {'x ref':>6}")
    for config in args.configs:
        print(f"{config:<28} {best[config]:>11.0f} {best[config] / ref:>6.2f}")


if __name__ == "__main__":
    main()
