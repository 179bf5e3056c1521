"""The batched env's props: placed when the sub-envs are handed out (not on every step), where
the single env's step leaves them, bit for bit."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

from sgc_env.envs.vector import batch as batch_module
from sgc_env.simulator import pybullet


def _prop_positions(env: gym.Env, client: int) -> list[tuple[float, ...]]:
    return [pybullet.getBasePositionAndOrientation(uid, physicsClientId=client)[0]
            for uid in env._prop_uids]  # fmt: skip


@pytest.mark.parametrize("fast_min", [1, 8])  # the numpy path, and each sub-env's own step
def test_props_of_handed_out_sub_envs_are_where_single_envs_leave_them(
    fast_min: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(batch_module, "FAST_MIN_ENVS", fast_min)
    env_id, n = "SGCThreeRodsRandom-v3", 2
    vec = gym.make_vec(env_id, n, vectorization_mode="vector_entry_point")
    singles = [gym.make(env_id).unwrapped for _ in range(n)]
    try:
        assert (vec.unwrapped._batch.fast is not None) == (fast_min == 1)
        vec.reset(seed=5)
        for i, env in enumerate(singles):
            env.reset(seed=5 + i)
        actions = np.zeros((n, *vec.single_action_space.shape), np.float32)
        for stretch in (7, 4):  # handed out once between: the steps go on from the objects
            for _ in range(stretch):
                vec.step(actions)
                for i, env in enumerate(singles):
                    env.step(actions[i])
            for i, sub in enumerate(vec.unwrapped.envs):
                assert sub._tick == singles[i]._tick
                moved = _prop_positions(sub, sub.sim.prop_client)
                assert moved == _prop_positions(singles[i], singles[i].sim.client)
                assert moved != [tuple(p.position) for p in sub.scenario.props]  # they move
    finally:
        vec.close()
        for env in singles:
            env.close()
