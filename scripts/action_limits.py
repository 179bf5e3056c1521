"""Largest action policies ask for, before the env clips it to [-1, 1] (the force and torque
caps), and their cost per step, on the paper's three-rod scene and held-out random rod scenes.

An entry beyond 1 means the policy asked for more force or torque than the body's cap
(``tau = R0 diag(torque_scale) R0^T a``, ``F = force_limit a``): the env clips it and the body
leaves the plan. Prints one row per scene: per policy the largest entry and whether every
goal was met to 1e-9; then each policy's mean time per ``predict`` (its episode-start work
included) and its ratio to the first policy's, measured in this run. Exit status 1 when the
first policy's entry exceeds 1.

    PYTHONPATH=$PWD .venv/bin/python scripts/action_limits.py \
        --policy expert-smooth,minimum-jerk,expert --episodes 10
"""

from __future__ import annotations

import argparse
import sys
import time
from typing import Any

import gymnasium as gym
import numpy as np

import sgc_env  # noqa: F401  (registers the envs)
from baselines.policies import make_policy
from sgc_env.defaults import EVAL_SEED


def largest_action(policy: str, env_id: str, seed: int) -> dict[str, Any]:
    """One episode: the largest |action| entry the policy asked for, goals met (1e-9) / goals,
    steps and seconds spent in ``predict``."""
    env = gym.make(env_id)
    try:
        obs, _ = env.reset(seed=seed)
        actor = make_policy(policy, env)
        largest, met, goals, steps, seconds, done = 0.0, 0, 0, 0, 0.0, False
        while not done:
            start = time.perf_counter()
            action, _ = actor.predict(obs, episode_start=np.array([steps == 0]))
            seconds += time.perf_counter() - start
            steps += 1
            largest = max(largest, float(np.max(np.abs(action))))
            obs, _, terminated, truncated, info = env.step(action)
            done = terminated or truncated
            for event in info.get("goal_reached", []):
                goals += 1
                errors = (event["position_error"], event["orientation_error"])
                met += all(e is None or e <= 1e-9 for e in errors)
        return {"env": env_id, "seed": seed, "largest": largest, "met": met, "goals": goals,
                "steps": steps, "seconds": seconds}  # fmt: skip
    finally:
        env.close()


def rows(policy: str, episodes: int, seed: int) -> list[dict[str, Any]]:
    """The paper's scene, then ``episodes`` random rod scenes from ``seed``."""
    out = [largest_action(policy, "SGCThreeRods-v2", 0)]
    out += [largest_action(policy, "SGCThreeRodsRandom-v3", seed + i) for i in range(episodes)]
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--policy", default="expert", help="one spec or several, comma-separated")
    parser.add_argument("--episodes", type=int, default=5, help="random scenes (default 5)")
    parser.add_argument("--seed", type=int, default=EVAL_SEED)
    args = parser.parse_args(argv)
    policies = args.policy.split(",")
    tables = {p: rows(p, args.episodes, args.seed) for p in policies}
    print("| env | seed | " + " | ".join(f"{p}: largest entry, goals met" for p in policies) + " |")
    print("|---|---|" + "---|" * len(policies))
    for i, first in enumerate(tables[policies[0]]):
        cells = [f"{t[i]['largest']:.3f}, {t[i]['met']}/{t[i]['goals']}" for t in tables.values()]
        print(f"| {first['env']} | {first['seed']} | " + " | ".join(cells) + " |")
    costs = {
        p: sum(r["seconds"] for r in t) / sum(r["steps"] for r in t) for p, t in tables.items()
    }
    for p, cost in costs.items():
        ratio = cost / costs[policies[0]]
        print(f"{p}: {1e3 * cost:.2f} ms per step, {ratio:.2f}x {policies[0]}'s (this run)")
    worst = max(r["largest"] for r in tables[policies[0]])
    print(f"largest entry of {policies[0]}: {worst:.3f} (cap 1)")
    return 0 if worst <= 1.0 else 1


if __name__ == "__main__":
    sys.exit(main())
