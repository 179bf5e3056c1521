"""How the smooth rule splits the courses (baselines/controllers/smooth_table.py) and what its table
costs.

On the paper's three-rod scene and held-out random rod scenes: the sub-course lengths per
track kind (ticks between two sub-goals; a one-tick sub-course is the reference's next
sample) and the time to build each scene's table.

    PYTHONPATH=$PWD .venv/bin/python scripts/subgoal_stats.py --episodes 10
"""

from __future__ import annotations

import argparse
import sys
import time

import gymnasium as gym
import numpy as np

import sgc_env  # noqa: F401  (registers the envs)
from baselines.common.sub_envs import base_env
from baselines.controllers.smooth_table import smooth_table
from sgc_env.defaults import EVAL_SEED


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--episodes", type=int, default=5, help="random scenes (default 5)")
    parser.add_argument("--seed", type=int, default=EVAL_SEED)
    args = parser.parse_args(argv)
    scenes = [("SGCThreeRods-v2", 0)]
    scenes += [("SGCThreeRodsRandom-v3", args.seed + i) for i in range(args.episodes)]
    lengths: dict[str, list[np.ndarray]] = {"position": [], "orientation": []}
    seconds = []
    for env_id, seed in scenes:
        env = gym.make(env_id)
        env.reset(seed=seed)
        start = time.perf_counter()
        table = smooth_table(base_env(env).scenario)
        seconds.append(time.perf_counter() - start)
        env.close()
        tracks = {(b, name): c.subgoals for (b, name, _), c in table.items()}
        for (_, name), sub in tracks.items():
            lengths[name].append(np.diff((0, *sub.ticks)))
    print("| track | sub-courses | mean ticks | ticks in 1-tick sub-courses | in 4-8 tick ones |")
    print("|---|---|---|---|---|")
    for name, parts in lengths.items():
        n = np.concatenate(parts)
        one, long = 100 * n[n == 1].sum() / n.sum(), 100 * n[n >= 4].sum() / n.sum()
        print(f"| {name} | {n.size} | {n.mean():.1f} | {one:.1f} % | {long:.1f} % |")
    print(f"table build per scene: {min(seconds):.2f}-{max(seconds):.2f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
