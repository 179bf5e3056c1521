"""PyBullet's ``stepSimulation`` cost per body in one world of N free bodies without collision
shapes (the bodies of the batched env's worlds): why ``sgc_env.envs.vector.batch`` spreads its
scenes over worlds of about ``SHARD_OBJECTS`` objects. Prints us per body-step for each N.

    .venv/bin/python scripts/bench_world_step.py --n 1 2 4 8 16 32 64 128 256
"""

from __future__ import annotations

import argparse
import time

from sgc_env.simulator import pybullet as pb


def per_body_step_us(n: int, steps: int) -> float:
    """Seconds per ``stepSimulation`` of a world of ``n`` free bodies, per body, in us."""
    c = pb.connect(pb.DIRECT)
    try:
        pb.setGravity(0.0, 0.0, -9.81, physicsClientId=c)
        for _ in range(n):
            uid = pb.createMultiBody(baseMass=1.0, physicsClientId=c)
            pb.changeDynamics(
                uid, -1, linearDamping=0.0, angularDamping=0.0,
                localInertiaDiagonal=[0.1, 0.1, 0.01], physicsClientId=c,
            )  # fmt: skip
        started = time.perf_counter()
        for _ in range(steps):
            pb.stepSimulation(physicsClientId=c)
        return (time.perf_counter() - started) / steps / n * 1e6
    finally:
        pb.disconnect(c)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", nargs="+", type=int, default=[1, 4, 16, 64, 256])
    parser.add_argument("--steps", type=int, default=50)
    parser.add_argument("--repeats", type=int, default=3, help="the best of this many runs")
    args = parser.parse_args()
    for n in args.n:
        best = min(per_body_step_us(n, args.steps) for _ in range(args.repeats))
        print(f"{n:5d} bodies  {best:8.2f} us per body-step", flush=True)


if __name__ == "__main__":
    main()
