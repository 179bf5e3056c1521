"""The fixed reference of the env timings: a bare PyBullet loop doing an env's physics.

The same bodies and props in their own client, the same number of substeps, the same
applyExternalForce/Torque (and prop placement) calls per substep and one
getBasePositionAndOrientation + getBaseVelocity per body per control step, with the client
passed positionally as the env's simulator does (keywords cost PyBullet about 0.13 us a call).
What the env adds on top is the Python of its contract: observation, reward, info, checks.
"""

from __future__ import annotations

import time
from typing import Any

import gymnasium as gym
import numpy as np

from sgc_env.envs import SGCEnv
from sgc_env.simulator import Simulator, pybullet

__all__ = ["BareLoop", "env_step_us", "fixed_env", "hover_action", "reset_us"]


class BareLoop:
    """The same physics as ``env`` driven directly through PyBullet, in its own client."""

    def __init__(self, env: SGCEnv) -> None:
        s = env.scenario
        self.substeps, self.use_torque = env.substeps, env.use_torque
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
        use_torque, substeps = self.use_torque, self.substeps
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

    def close(self) -> None:
        self.sim.close()


def hover_action(env: Any) -> np.ndarray:
    """The action that holds every body of ``env`` against gravity (forces only)."""
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


def reset_us(env: gym.Env, n: int, **kwargs: Any) -> float:
    """Microseconds per ``env.reset(**kwargs)`` over ``n`` resets after a first one."""
    env.reset(**kwargs)
    t0 = time.perf_counter()
    for _ in range(n):
        env.reset(**kwargs)
    return (time.perf_counter() - t0) / n * 1e6


def fixed_env(env_id: str) -> tuple[SGCEnv, SGCEnv]:
    """The env as registered (reset at seed 0) and a plain SGCEnv on that same scenario, on
    the id's view and reward (they cost per step): timing the fixed one keeps random-scene
    draws out of the step and reset figures."""
    made = gym.make(env_id).unwrapped
    if not isinstance(made, SGCEnv):
        raise TypeError(f"{env_id} is not an SGCEnv id")
    made.reset(seed=0)
    spec_kwargs = gym.spec(env_id).kwargs
    view = {k: v for k, v in spec_kwargs.items() if k in ("observation", "reward")}
    fixed = SGCEnv(made.scenario, **view)
    fixed.reset()
    return made, fixed
