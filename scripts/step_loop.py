"""A bare loop of hover steps on one env, to count the instructions a step costs.

Run it under callgrind at two step counts and divide the difference of the totals by the
difference of the counts; instruction counts, unlike timings, do not change on a busy machine:

    valgrind --tool=callgrind --callgrind-out-file=/dev/null \\
        .venv/bin/python scripts/step_loop.py --checkout . --env point --steps 1200

``--checkout`` puts another worktree's ``sgc_env`` first on the path (compare two commits).
``--env`` is a random preset (``point``, ``rod``, drawn at seed 0) or a built-in scenario name.
"""

from __future__ import annotations

import argparse
from pathlib import Path


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--checkout", type=Path, default=Path(__file__).resolve().parents[1])
    parser.add_argument("--env", default="point")
    parser.add_argument("--steps", type=int, default=1000)
    args = parser.parse_args()
    from baselines.timing.bare import hover_action
    from baselines.timing.checkouts import load_sgc_env

    SGCEnv = load_sgc_env(args.checkout.resolve()).envs.SGCEnv  # noqa: N806  (the checkout's class)

    preset = args.env in ("point", "rod")
    made = SGCEnv(random_scenario=args.env) if preset else SGCEnv(args.env)
    made.reset(seed=0)
    env = SGCEnv(made.scenario)
    made.close()
    env.reset()
    action = hover_action(env)
    for _ in range(args.steps):
        _, _, terminated, truncated, _ = env.step(action)
        if terminated or truncated:
            env.reset(options={"scenario": env.scenario})
    env.close()


if __name__ == "__main__":
    main()
