"""What the plan check of ``resolve_scenario`` would add to a random-scenario reset.

For each preset it draws scenarios (the reference: what a reset does today), then runs the
analytic-plan feasibility check (``sgc_env.scenario.demand.body_demands``) on the same draws and on
the built-in scenes, and prints milliseconds per call and the ratio to the draw (the check is
skipped on random resets because of this ratio; their analytic bound is tested instead). Last,
the three-rod demo's force estimate next to the force the expert applies.

    PYTHONPATH=$PWD .venv/bin/python scripts/bench_plan_check.py --draws 20
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from sgc_env.scenario import builtin_scenarios, load_scenario
from sgc_env.scenario.demand import body_demands
from sgc_env.scenes import PRESETS, random_scenario


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--draws", type=int, default=20)
    args = parser.parse_args()
    body_demands(load_scenario("point_three_goals"))  # imports the planner and scipy once
    print(f"{'scene':<20} {'draw ms':>9} {'check ms':>9} {'check / draw':>13}")
    for preset in PRESETS:
        rng = np.random.default_rng(0)
        started = time.perf_counter()
        scenes = [random_scenario(rng, preset) for _ in range(args.draws)]
        draw = (time.perf_counter() - started) / args.draws
        started = time.perf_counter()
        for s in scenes:
            body_demands(s)
        check = (time.perf_counter() - started) / args.draws
        print(f"{'random ' + preset:<20} {draw * 1e3:9.2f} {check * 1e3:9.2f} {check / draw:13.0f}")
    for name in builtin_scenarios():
        s = load_scenario(name)
        started = time.perf_counter()
        body_demands(s)
        print(f"{name:<20} {'':>9} {(time.perf_counter() - started) * 1e3:9.1f}")
    print("\nthree_rods: peak force (N) the check estimates vs the expert applies")
    for b, estimate, applied in zip(
        load_scenario("three_rods").bodies,
        body_demands(load_scenario("three_rods")),
        expert_peak_forces("three_rods"),
        strict=True,
    ):
        print(f"  {b.name:<10} {estimate.force:7.1f} {applied:7.1f}  (limit {b.force_limit:g})")


def expert_peak_forces(name: str) -> list[float]:
    """Largest |force| the analytic expert applies to each body over a seeded episode."""
    from baselines import SGCExpert
    from sgc_env.envs import SGCEnv

    env = SGCEnv(name)
    expert = SGCExpert(env)
    obs, _ = env.reset(seed=0)
    peak = np.zeros(len(env.scenario.bodies))
    done = False
    while not done:
        action, _ = expert.predict(obs, deterministic=True)
        obs, _, terminated, truncated, info = env.step(action)
        peak = np.maximum(peak, np.linalg.norm(info["force"], axis=1))
        done = terminated or truncated
    env.close()
    return peak.tolist()


if __name__ == "__main__":
    main()
