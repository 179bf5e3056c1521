"""baselines.timing: the bare loop does the env's physics, and the tables say what they time."""

from __future__ import annotations

import math

import gymnasium as gym
import numpy as np

import sgc_env  # noqa: F401  (registers the ids)
from baselines.timing.bare import BareLoop, env_step_us, fixed_env, hover_action, reset_us
from baselines.timing.env_step import env_table


def test_the_bare_loop_holds_the_env_bodies_and_props() -> None:
    made, env = fixed_env("SGCThreeRods-v2")
    bare = BareLoop(env)
    try:
        assert len(bare.uids) == len(env.scenario.bodies) and len(bare.props) == len(
            env.scenario.props
        )
        assert (bare.substeps, bare.use_torque) == (env.substeps, env.use_torque)
        assert math.isfinite(bare.run_us(5)) and bare.run_us(5) > 0.0
    finally:
        bare.close()
        env.close()
        made.close()


def test_the_hover_action_holds_a_body_still() -> None:
    made, env = fixed_env("SGCPoint-v1")
    try:
        _, info = env.reset()
        start = info["body_velocity"].copy()
        for _ in range(20):
            _, _, _, _, info = env.step(hover_action(env))
        # free fall would change it by 3.3 m/s in these 20 steps; float32 rounding of the action
        # leaves micro-metres per second
        assert np.allclose(info["body_velocity"], start, atol=1e-6)
    finally:
        env.close()
        made.close()


def test_the_step_and_reset_timers_count_per_call() -> None:
    made, env = fixed_env("SGCRod-v1")
    try:
        assert env_step_us(env, 20, hover_action(env)) > 0.0
        assert reset_us(env, 3) > 0.0
    finally:
        env.close()
        made.close()


def test_the_env_table_has_one_row_per_id() -> None:
    lines = list(env_table(["SGCPoint-v1", "SGCThreeRods-v2"], 20, 4, 2, 2))
    assert lines[0].split()[:3] == ["id", "env", "steps/s"] and set(lines[1]) == {"-"}
    rows = {line.split()[0]: line.split()[1:] for line in lines[2:]}
    assert list(rows) == ["SGCPoint-v1", "SGCThreeRods-v2"]
    assert all(float(v) > 0 for v in rows["SGCPoint-v1"])  # a random-scene id: draws timed
    assert rows["SGCThreeRods-v2"][-1] == "nan"  # a fixed scene draws nothing
    assert gym.spec("SGCThreeRods-v2").kwargs.get("random_scenario") is None
