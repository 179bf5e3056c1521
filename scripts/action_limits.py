"""Largest action a policy asks for, before the env clips it to [-1, 1] (its force and torque
caps), on the paper's three-rod scene and on held-out random rod scenes.

An entry beyond 1 means the policy asked for more force or torque than the body's cap
(``tau = R0 diag(torque_scale) R0^T a``, ``F = force_limit a``): the env clips it and the body
leaves the plan. Prints one row per scene with the largest entry and whether every goal was
met; exit status 1 when an entry exceeds 1.

    PYTHONPATH=$PWD .venv/bin/python scripts/action_limits.py --policy expert-smooth --episodes 10
"""

from __future__ import annotations

import argparse
import sys
from typing import Any

import gymnasium as gym
import numpy as np

import sgc_env  # noqa: F401  (registers the envs)
from baselines.policies import make_policy
from sgc_env.defaults import EVAL_SEED


def largest_action(policy: str, env_id: str, seed: int) -> dict[str, Any]:
    """One episode: the largest |action| entry the policy asked for, goals met / goals."""
    env = gym.make(env_id)
    try:
        obs, _ = env.reset(seed=seed)
        actor = make_policy(policy, env)
        largest, met, goals, first, done = 0.0, 0, 0, True, False
        while not done:
            action, _ = actor.predict(obs, episode_start=np.array([first]))
            first = False
            largest = max(largest, float(np.max(np.abs(action))))
            obs, _, terminated, truncated, info = env.step(action)
            done = terminated or truncated
            for event in info.get("goal_reached", []):
                goals += 1
                errors = (event["position_error"], event["orientation_error"])
                met += all(e is None or e <= 1e-9 for e in errors)
        return {"env": env_id, "seed": seed, "largest": largest, "met": met, "goals": goals}
    finally:
        env.close()


def rows(policy: str, episodes: int, seed: int) -> list[dict[str, Any]]:
    out = [largest_action(policy, "SGCThreeRods-v1", 0)]
    out += [largest_action(policy, "SGCThreeRodsRandom-v2", seed + i) for i in range(episodes)]
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--policy", default="expert")
    parser.add_argument("--episodes", type=int, default=5, help="random scenes (default 5)")
    parser.add_argument("--seed", type=int, default=EVAL_SEED)
    args = parser.parse_args(argv)
    table = rows(args.policy, args.episodes, args.seed)
    print(f"| env | seed | largest action entry ({args.policy}) | goals met (1e-9) |")
    print("|---|---|---|---|")
    for r in table:
        print(f"| {r['env']} | {r['seed']} | {r['largest']:.3f} | {r['met']}/{r['goals']} |")
    worst = max(r["largest"] for r in table)
    print(f"largest: {worst:.3f} (cap 1)")
    return 0 if worst <= 1.0 else 1


if __name__ == "__main__":
    sys.exit(main())
