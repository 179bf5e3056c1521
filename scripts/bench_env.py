"""Control steps per second of every registered env against a bare PyBullet loop.

Every id of ``sgc_env.ENV_IDS``, each on its own view and reward.

The bare loop does the same physics in the same process: the same bodies and props, the same
number of substeps, the same applyExternalForce/Torque (and prop placement) calls per substep,
and one getBasePositionAndOrientation + getBaseVelocity per body per control step. Reset time is
the mean of ``env.reset()`` on the unwrapped env with a fixed scenario (random-scenario envs
are also timed with their per-reset scenario draw).

    .venv/bin/python scripts/bench_env.py [--steps 10000] [--resets 1000] [--rounds 20]
"""

from __future__ import annotations

import argparse
import time

import gymnasium as gym
import numpy as np

import sgc_env
from sgc_env.envs import SGCEnv
from sgc_env.simulator import Simulator, pybullet


class BareLoop:
    """The same physics as ``env`` driven directly through PyBullet, in its own client."""

    def __init__(self, env: SGCEnv) -> None:
        s = env.scenario
        self.env = env
        self.sim = Simulator(sim_frequency=env.sim_frequency)
        self.sim.set_gravity(s.gravity)
        self.uids = [
            self.sim.add_body(b.name, b.shape, b.size, b.mass, b.color, collisions=b.collisions).uid
            for b in s.bodies
        ]
        self.props = [
            self.sim.add_body(
                p.name, p.shape, p.size, 0.0, p.color, kinematic=True, collisions=p.collisions
            ).uid
            for p in s.props
        ]
        for uid, b in zip(self.uids, s.bodies, strict=True):
            self.sim.reset_body(
                uid, b.position, b.orientation, b.linear_velocity, b.angular_velocity
            )
        self.force = [(0.0, 0.0, b.mass * 9.81) for b in s.bodies]

    def run_us(self, steps: int) -> float:
        """Microseconds per control step."""
        pb, c = pybullet, self.sim.client
        apply_f, apply_t, step = pb.applyExternalForce, pb.applyExternalTorque, pb.stepSimulation
        get_p, get_v = pb.getBasePositionAndOrientation, pb.getBaseVelocity
        reset = pb.resetBasePositionAndOrientation
        world, ident = pb.WORLD_FRAME, (0.0, 0.0, 0.0, 1.0)
        uids, props, force, torque = self.uids, self.props, self.force, (0.0, 0.0, 0.0)
        use_torque, substeps = self.env.use_torque, self.env.substeps
        positions = [get_p(u, c)[0] for u in uids]
        t0 = time.perf_counter()
        for _ in range(steps):
            for _k in range(substeps):
                for uid in props:
                    reset(uid, (0.0, 0.0, 1.0), ident, c)
                for i, uid in enumerate(uids):
                    apply_f(uid, -1, force[i], positions[i], world, c)
                    if use_torque:
                        apply_t(uid, -1, torque, world, c)
                step(c)
            for i, uid in enumerate(uids):
                positions[i] = get_p(uid, c)[0]
                get_v(uid, c)
        return (time.perf_counter() - t0) / steps * 1e6


def hover_action(env: SGCEnv) -> np.ndarray:
    action = np.zeros(env.action_space.shape, np.float32)
    per = 6 if env.use_torque else 3
    for i, b in enumerate(env.scenario.bodies):
        action[i * per + 2] = b.mass * 9.81 / b.force_limit
    return action


def env_step_us(env: SGCEnv, steps: int, action: np.ndarray) -> float:
    """Microseconds per env.step (resets excluded from the timing)."""
    total, done_steps = 0.0, 0
    while done_steps < steps:
        t0 = time.perf_counter()
        _, _, terminated, truncated, _ = env.step(action)
        total += time.perf_counter() - t0
        done_steps += 1
        if terminated or truncated:
            env.reset(options={"scenario": env.scenario})
    return total / steps * 1e6


def reset_us(env: gym.Env, n: int, **kwargs) -> float:
    env.reset(**kwargs)
    t0 = time.perf_counter()
    for _ in range(n):
        env.reset(**kwargs)
    return (time.perf_counter() - t0) / n * 1e6


def fixed_env(env_id: str) -> tuple[SGCEnv, SGCEnv]:
    """The env as registered (reset at seed 0) and a plain SGCEnv on that same scenario.

    Timing the fixed one keeps random-scenario draws out of the step and reset figures.
    """
    made = gym.make(env_id).unwrapped
    made.reset(seed=0)
    view = {k: v for k, v in gym.spec(env_id).kwargs.items() if k in ("observation", "reward")}
    fixed = SGCEnv(made.scenario, **view)  # the id's view and reward: they cost per step
    fixed.reset()
    return made, fixed


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=10000)
    parser.add_argument("--resets", type=int, default=1000)
    parser.add_argument("--rounds", type=int, default=20, help="interleaved rounds; best is kept")
    parser.add_argument(
        "--draws", type=int, default=20,
        help="random-scene resets timed per id",
    )  # fmt: skip
    args = parser.parse_args()
    ids = sgc_env.ENV_IDS
    width = max(len(env_id) for env_id in ids)
    header = (
        f"{'id':{width}} {'env steps/s':>12} {'bare steps/s':>13} {'ratio':>6} "
        f"{'reset us':>9} {'draw+reset us':>14}"
    )
    print(header)
    print("-" * len(header))
    for env_id in ids:
        made, fixed = fixed_env(env_id)
        bare = BareLoop(fixed)
        action = hover_action(fixed)
        chunk = max(args.steps // args.rounds, 1)
        env_us = bare_us = fixed_reset = float("inf")
        for _ in range(args.rounds):  # interleaved, best of rounds: robust to a busy machine
            env_us = min(env_us, env_step_us(fixed, chunk, action))
            bare_us = min(bare_us, bare.run_us(chunk))
            fixed_reset = min(fixed_reset, reset_us(fixed, max(args.resets // args.rounds, 1)))
        bare.sim.close()
        draw = reset_us(made, max(args.draws, 1)) if made._random_config else float("nan")
        print(
            f"{env_id:{width}} {1e6 / env_us:12.0f} {1e6 / bare_us:13.0f} {env_us / bare_us:6.2f} "
            f"{fixed_reset:9.1f} {draw:14.1f}"
        )
        fixed.close()
        made.close()


if __name__ == "__main__":
    main()
