"""Cost of the analytic expert's action next to the physics it drives.

For each env, measured in the same run and process:

* ``bare``: a bare PyBullet loop doing the same physics as one control step (the substeps,
  applyExternalForce/Torque per body per substep, one state read per body), from
  :mod:`baselines.timing.bare`;
* ``env``: the env's own ``step`` (hovering action, resets excluded);
* ``expert``: ``SGCExpert.action`` on observations recorded from expert episodes. Every
  observation is timed ``--repeats`` times in interleaved rounds and its minimum kept (robust to
  a shared machine); reported are the median and minimum over mid-course observations (no goal
  on the next tick), the median over goal ticks (exact Newton torque), and the mean over whole
  episodes, all in microseconds, per control step and per body; and the mid-course median of
  ``SGCExpert(refine=False)`` (no correction step on the torque between goals) on the same
  observations.

    .venv/bin/python scripts/bench_expert.py [--episodes 20] [--repeats 7] [--steps 3000]
"""

from __future__ import annotations

import argparse
import statistics
import time

import gymnasium as gym
import numpy as np

import sgc_env  # noqa: F401  (registers the env ids)
from baselines.controllers.expert import GOAL_TICK_SLACK, SGCExpert
from baselines.timing.bare import BareLoop, env_step_us, fixed_env, hover_action

ENV_IDS = ("SGCRod-v1", "SGCThreeRods-v2")


def record_episodes(env_id: str, episodes: int) -> tuple[SGCExpert, list[np.ndarray], list[bool]]:
    """Observations of expert episodes and, for each, whether a goal is on the next tick."""
    env = gym.make(env_id)
    expert = SGCExpert(env)
    base = env.unwrapped
    layout, period = base.layout, expert.model.control_dt
    observations, goal_tick = [], []
    for seed in range(episodes):
        obs, _ = env.reset(seed=seed)
        done = False
        while not done:
            observations.append(obs)
            goal_tick.append(_goal_on_next_tick(obs, layout, period))
            obs, _, terminated, truncated, _ = env.step(expert.action(obs))
            done = terminated or truncated
    env.close()
    return expert, observations, goal_tick


def _goal_on_next_tick(obs: np.ndarray, layout, period: float) -> bool:
    values = obs.astype(np.float64)
    for body in range(layout.n_bodies):
        for track in ("position", "orientation"):
            flags = values[layout.body_slice(body, f"{track}_flags")]
            left = values[layout.body_slice(body, f"{track}_time_left")][0] + values[
                layout.body_slice(body, f"{track}_time_left_residual")
            ][0]
            if flags[0] > 0.5 and 0.5 * period < left <= period * (1.0 + GOAL_TICK_SLACK):
                return True
    return False


def time_actions(expert: SGCExpert, observations: list[np.ndarray], repeats: int) -> np.ndarray:
    """Per observation, the minimum over ``repeats`` interleaved rounds (microseconds)."""
    action = expert.action
    for obs in observations[: min(200, len(observations))]:  # warm-up
        action(obs)
    best = np.full(len(observations), np.inf)
    clock = time.perf_counter
    for _ in range(repeats):
        for i, obs in enumerate(observations):
            t0 = clock()
            action(obs)
            dt = clock() - t0
            if dt < best[i]:
                best[i] = dt
    return best * 1e6


def physics_us(env_id: str, steps: int, rounds: int) -> tuple[float, float, int]:
    """Best-of-rounds microseconds per control step: bare PyBullet loop and env.step."""
    made, fixed = fixed_env(env_id)
    bare = BareLoop(fixed)
    action = hover_action(fixed)
    chunk = max(steps // rounds, 1)
    env_step_us(fixed, chunk, action)  # warm-up
    bare.run_us(chunk)
    env_us = bare_us = float("inf")
    for _ in range(rounds):
        env_us = min(env_us, env_step_us(fixed, chunk, action))
        bare_us = min(bare_us, bare.run_us(chunk))
    n_bodies = len(made.scenario.bodies)
    bare.sim.close()
    fixed.close()
    made.close()
    return bare_us, env_us, n_bodies


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--episodes", type=int, default=20, help="recorded episodes per env")
    parser.add_argument("--repeats", type=int, default=7, help="timings per observation")
    parser.add_argument("--steps", type=int, default=3000, help="physics steps per env")
    parser.add_argument("--rounds", type=int, default=5, help="physics rounds; best is kept")
    args = parser.parse_args()
    for env_id in ENV_IDS:
        episodes = args.episodes if env_id == "SGCRod-v1" else 1  # the three-rod demo is fixed
        expert, observations, goal_tick = record_episodes(env_id, episodes)
        cost = time_actions(expert, observations, args.repeats)
        unrefined = SGCExpert(model=expert.model, refine=False)
        cost_unrefined = time_actions(unrefined, observations, args.repeats)
        mid = [c for c, g in zip(cost, goal_tick, strict=True) if not g]
        goals = [c for c, g in zip(cost, goal_tick, strict=True) if g]
        bare_us, env_us, n = physics_us(env_id, args.steps, args.rounds)
        mid_median = statistics.median(mid)
        print(f"{env_id}: {n} bod{'y' if n == 1 else 'ies'}, {len(observations)} observations "
              f"({len(goals)} goal ticks) from {episodes} episode(s)")  # fmt: skip
        rows = [
            ("bare PyBullet step", bare_us),
            ("env.step", env_us),
            ("expert, mid-course median", mid_median),
            ("expert, mid-course min", min(mid)),
            ("expert, goal-tick median", statistics.median(goals) if goals else float("nan")),
            ("expert, episode mean", float(np.mean(cost))),
            ("  refine=False, mid median", statistics.median(
                [c for c, g in zip(cost_unrefined, goal_tick, strict=True) if not g]
            )),
        ]
        print(f"  {'':28} {'us/step':>9} {'us/body':>9}")
        for name, value in rows:
            print(f"  {name:28} {value:9.1f} {value / n:9.1f}")
        print(f"  expert mid-course median / bare step: {mid_median / bare_us:.2f}; "
              f"/ env.step: {mid_median / env_us:.2f}; "
              f"episode mean / env.step: {float(np.mean(cost)) / env_us:.2f}")  # fmt: skip


if __name__ == "__main__":
    main()
