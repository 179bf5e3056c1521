"""Calibrate ``sgc_env.random_three_rods.demand_estimate`` against the expert inside PyBullet.

Draws three-rod scenes with unit factors and no rejection (limits 1e6, so nothing clips),
drives each with ``SGCExpert`` and prints, per rod, the largest |force| and |torque| the
expert applied over the estimate's unit-factor terms. ``FORCE_FACTOR`` and ``TORQUE_FACTOR``
in ``sgc_env/random_three_rods.py`` are the largest ratios printed here times a margin.
It also prints the share of draws the default config rejects and the mean reset time of
``SGCInterceptRandom-v0`` and ``SGCThreeRodsRandom-v0``.

    .venv/bin/python scripts/calibrate_random_scenes.py [--draws 60] [--resets 20]
"""

from __future__ import annotations

import argparse
import time

import gymnasium as gym
import numpy as np

import sgc_env  # noqa: F401  (registers the ids)
from baselines.expert import SGCExpert
from sgc_env.envs import SGCEnv
from sgc_env.random_three_rods import (
    RandomThreeRodsConfig,
    demand_estimate,
    random_three_rods,
)


def _ratios(draws: int) -> tuple[np.ndarray, np.ndarray]:
    loose = RandomThreeRodsConfig(
        force_limit=1e6, torque_limit=1e6, force_factor=1.0, torque_factor=1.0
    )
    env = SGCEnv(random_scenario=loose)
    expert = SGCExpert(env)
    force_ratio, torque_ratio = [], []
    for seed in range(draws):
        obs, _ = env.reset(seed=seed)
        estimate = demand_estimate(env.scenario, 1.0, 1.0)
        wrench, done = [], False
        while not done:
            action, _ = expert.predict(obs)
            wrench.append(action.reshape(-1, 6) * 1e6)
            obs, _, terminated, truncated, _ = env.step(action)
            done = terminated or truncated
        w = np.asarray(wrench)
        force = np.linalg.norm(w[:, :, :3], axis=2).max(axis=0)
        torque = np.linalg.norm(w[:, :, 3:], axis=2).max(axis=0)
        for k, (body, (f_est, t_est)) in enumerate(zip(env.scenario.bodies, estimate, strict=True)):
            weight = body.mass * 9.81
            force_ratio.append((force[k] - weight) / (f_est - weight))
            torque_ratio.append(torque[k] / t_est)
    env.close()
    return np.asarray(force_ratio), np.asarray(torque_ratio)


def _rejected_share(draws: int) -> float:
    cfg = RandomThreeRodsConfig()
    rng = np.random.default_rng(0)
    rejected = 0
    for _ in range(draws):
        s = random_three_rods(rng, RandomThreeRodsConfig(force_limit=1e6, torque_limit=1e6))
        demand = demand_estimate(s, cfg.force_factor, cfg.torque_factor)
        rejected += any(f > cfg.force_limit or t > cfg.torque_limit for f, t in demand)
    return rejected / draws


def _reset_ms(env_id: str, resets: int) -> float:
    env = gym.make(env_id).unwrapped
    env.reset(seed=0)
    start = time.perf_counter()
    for seed in range(1, resets + 1):
        env.reset(seed=seed)
    env.close()
    return (time.perf_counter() - start) / resets * 1e3


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--draws", type=int, default=60)
    parser.add_argument("--resets", type=int, default=20)
    args = parser.parse_args()
    f, t = _ratios(args.draws)
    print(f"expert / estimate over {f.size} rods: force max {f.max():.2f} median "
          f"{np.median(f):.2f}; torque max {t.max():.2f} median {np.median(t):.2f}")  # fmt: skip
    print(f"share of draws the default config rejects: {_rejected_share(args.draws):.2f}")
    for env_id in ("SGCIntercept-v0", "SGCInterceptRandom-v0", "SGCThreeRods-v0",
                   "SGCThreeRodsRandom-v0"):  # fmt: skip
        print(f"{env_id}: reset {_reset_ms(env_id, args.resets):.1f} ms")


if __name__ == "__main__":
    main()
