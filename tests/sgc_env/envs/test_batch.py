"""The batched env equals N single envs bit for bit: observations, rewards, flags, infos and
goal events, through autoresets, under random actions, the expert's actions and pushes."""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np
import pytest

import sgc_env
from baselines import SGCExpert
from baselines.agents.pushes import Pushes, apply_random_push
from sgc_env.envs.rewards import REWARD_MODES, RewardMode, StepScore, effort
from sgc_env.envs.vector import batch as batch_module
from sgc_env.envs.vector import task as task_module
from sgc_env.envs.vector.vector_env import SGCVectorEnv, make_vec
from sgc_env.envs.views import ObservationView

# Random three-rod scenes cost ~0.2 s per reset (planned feasibility): fewer, shorter runs.
SIZES = {"SGCThreeRodsRandom-v3": (2, 40), "SGCThreeRods-v2": (2, 45)}


def _same(a: Any, b: Any) -> bool:
    if isinstance(a, dict):
        return a.keys() == b.keys() and all(np.array_equal(a[k], b[k]) for k in a)
    return bool(np.array_equal(a, b))


def _row(batch: Any, i: int) -> Any:
    return {k: v[i] for k, v in batch.items()} if isinstance(batch, dict) else batch[i]


@pytest.fixture(autouse=True)
def _numpy_step_from_one_env(monkeypatch: pytest.MonkeyPatch) -> None:
    """Small batches here step by the numpy path, as batches of FAST_MIN_ENVS or more do."""
    monkeypatch.setattr(batch_module, "FAST_MIN_ENVS", 1)


RL_ZOO_PATCH_KEY = "TimeLimit.truncated"
"""Added to a single env's last info by rl_zoo3's patched ``TimeLimit`` once any test imported
``rl_zoo3.gym_patches``: a wrapper's key, not the env's, and the vector env has no TimeLimit."""


def _check_info(vinfo: dict[str, Any], info: dict[str, Any], i: int) -> None:
    info = {k: v for k, v in info.items() if k != RL_ZOO_PATCH_KEY}
    for key, value in info.items():
        assert vinfo[f"_{key}"][i], key
        if isinstance(value, list):
            assert vinfo[key][i] == value, key  # goal events: dicts of plain numbers
        else:
            assert np.array_equal(vinfo[key][i], value), key
    for key in vinfo:
        if not key.startswith("_") and vinfo[f"_{key}"][i]:
            assert key in info, key


class _Expert:
    """The expert of one single env, rebuilt on reset (random scenes change the model)."""

    def __init__(self) -> None:
        self.expert: SGCExpert | None = None

    def __call__(self, env: gym.Env, obs: Any, fresh: bool) -> np.ndarray:
        if fresh or self.expert is None:
            self.expert = SGCExpert(env)
        return self.expert.predict(obs)[0].astype(np.float32)


def run_pair(
    env_id: str,
    n: int,
    steps: int,
    policy: str = "random",
    *,
    pushes: Pushes | None = None,
    seed: int = 11,
    **kwargs: Any,
) -> int:
    """Step ``gym.make_vec(env_id, n)`` (every id's vector entry point) beside n
    ``gym.make(env_id)`` envs (reset with seed + i, reset again on their own after an episode,
    as next-step autoreset does) and assert every output equal. Returns the number of autoresets."""
    vec = gym.make_vec(env_id, n, vectorization_mode="vector_entry_point", **kwargs)
    singles = [gym.make(env_id, **kwargs) for _ in range(n)]
    rng = np.random.default_rng(seed)
    experts = [_Expert() for _ in range(n)]
    push_rngs = [np.random.default_rng([seed, i]) for i in range(n)]
    resets = 0
    try:
        vobs, vinfo = vec.reset(seed=seed)
        obs = []
        for i, env in enumerate(singles):
            o, info = env.reset(seed=seed + i)
            assert _same(_row(vobs, i), o)
            _check_info(vinfo, info, i)
            obs.append(o)
        done = np.zeros(n, dtype=bool)
        fresh = np.ones(n, dtype=bool)
        shape = (n, *vec.single_action_space.shape)
        for tick in range(steps):
            if policy == "random":
                actions = rng.uniform(-1.2, 1.2, shape).astype(np.float32)
            else:
                actions = np.zeros(shape, np.float32)
                for i, env in enumerate(singles):
                    if done[i]:
                        continue
                    if pushes is not None:
                        state = push_rngs[i].bit_generator.state
                        flat = obs[i]["observation"] if isinstance(obs[i], dict) else obs[i]
                        pushed = apply_random_push(env, flat, pushes, push_rngs[i], tick)
                        twin = np.random.default_rng()
                        twin.bit_generator.state = state
                        vflat = _row(vobs, i)
                        vflat = vflat["observation"] if isinstance(vflat, dict) else vflat
                        sub_env = vec.unwrapped.envs[i]
                        twin_obs = apply_random_push(sub_env, vflat, pushes, twin, tick)
                        assert _same(twin_obs, pushed)
                        obs[i] = pushed
                    actions[i] = experts[i](env, obs[i], bool(fresh[i]))
            vobs, rewards, terminated, truncated, vinfo = vec.step(actions)
            for i, env in enumerate(singles):
                if done[i]:
                    o, info = env.reset()
                    r, term, trunc = 0.0, False, False
                    resets += 1
                else:
                    o, r, term, trunc, info = env.step(actions[i])
                assert _same(_row(vobs, i), o), (env_id, tick, i)
                assert rewards[i] == r and terminated[i] == term and truncated[i] == trunc
                _check_info(vinfo, info, i)
                obs[i] = o
            fresh = done.copy()
            done = terminated | truncated
    finally:
        vec.close()
        for env in singles:
            env.close()
    return resets


@pytest.mark.parametrize("env_id", sgc_env.ENV_IDS)
def test_every_id_equals_single_envs_under_random_actions(env_id: str) -> None:
    n, steps = SIZES.get(env_id, (3, 150))
    assert run_pair(env_id, n, steps) >= 2  # random actions leave the workspace: autoresets


@pytest.mark.parametrize("reward", REWARD_MODES)
@pytest.mark.parametrize("env_id", ["SGCRod-v1", "SGCThreeRods-v2", "SGCInterceptRandom-v1"])
def test_every_reward_mode_equals_single_envs(env_id: str, reward: str) -> None:
    assert run_pair(env_id, 2, 50, reward=reward, max_episode_steps=20) >= 2


class _Upright(RewardMode):
    """A reward of the caller's own: the time left to the first body's position goal, less
    the effort (plain arithmetic, so it runs on floats and on arrays alike)."""

    def reward(self, step: StepScore) -> Any:
        _, _, left, _, _ = step.tracks[0]
        return left - effort(step)


@pytest.mark.parametrize("env_id", ["SGCRod-v1", "SGCThreeRods-v2"])
def test_a_custom_reward_object_scores_the_same_in_both(env_id: str) -> None:
    assert run_pair(env_id, 2, 50, reward=_Upright(), max_episode_steps=20) >= 2


class _ClockView(ObservationView):
    """A view of the caller's own: each body's position and the time, from the record."""

    def space(self) -> gym.spaces.Box:
        return gym.spaces.Box(-1e5, 1e5, (3 * self.layout.n_bodies + 1,), np.float32)

    def observe(self, record: np.ndarray, constants: np.ndarray | None = None) -> np.ndarray:
        layout = self.layout
        parts = [record[..., layout.body_slice(j, "position")] for j in range(layout.n_bodies)]
        parts.append(record[..., layout.global_slice("time")])
        return np.concatenate(parts, axis=-1).astype(np.float32)


@pytest.mark.parametrize("env_id", ["SGCThreeRods-v2", "SGCPointGoal-v1"])
def test_a_custom_observation_view_observes_the_same_in_both(env_id: str) -> None:
    assert run_pair(env_id, 2, 50, observation=_ClockView(), max_episode_steps=20) >= 2
    with pytest.raises(ValueError, match="observation: unknown view 'pixels'.*planner"):
        gym.make(env_id, observation="pixels")


@pytest.mark.parametrize("env_id", ["SGCRod-v1", "SGCIntercept-v1", "SGCPointGoal-v1"])
def test_expert_actions_and_pushes_equal_single_envs(env_id: str) -> None:
    """The expert meets goals (goal events in the infos); pushes go through the sub-env's
    apply_impulse between steps; a short time limit makes the episodes end by truncation."""
    pushes = Pushes(scale=0.2, spin=0.5, prob=0.1)
    assert run_pair(env_id, 2, 90, "expert", pushes=pushes, max_episode_steps=40) >= 2


def test_gymnasium_conventions() -> None:
    vec = gym.make_vec("SGCRod-v1", num_envs=3, vectorization_mode="vector_entry_point")
    try:
        assert isinstance(vec.unwrapped, SGCVectorEnv)
        assert vec.metadata["autoreset_mode"] == gym.vector.AutoresetMode.NEXT_STEP
        single = gym.make("SGCRod-v1")
        assert vec.single_observation_space == single.observation_space
        assert vec.single_action_space == single.action_space
        assert vec.observation_space.shape == (3, *single.observation_space.shape)
        obs, info = vec.reset(seed=4)
        assert _same(obs[2], single.reset(seed=6)[0])  # sub-env i gets seed + i
        assert info["_time"].all() and info["goal_index"].shape == (3, 1)
        # reset_mask: only sub-env 1 starts over (from its own generator, not reseeded)
        vec.step(np.zeros((3, 6), np.float32))
        before = vec.envs[0].scenario
        obs2, info2 = vec.reset(options={"reset_mask": np.array([False, True, False])})
        assert info2["_time"].tolist() == [False, True, False]
        assert vec.envs[0].scenario is before and _same(obs2[0], obs[0]) is False
        single.reset(seed=5)
        assert _same(obs2[1], single.reset()[0])  # sub-env 1's second draw
        single.close()
        # options reach every sub-env: a scenario swap
        scenario = vec.envs[2].scenario
        obs3, _ = vec.reset(options={"scenario": scenario})
        assert all(env.scenario is scenario for env in vec.envs)
        assert _same(obs3[0], obs3[2])
        with pytest.raises(NotImplementedError, match="does not render"):
            vec.render()
    finally:
        vec.close()


@pytest.mark.parametrize("env_id", ["SGCRod-v1", "SGCThreeRods-v2", "SGCPointGoal-v1"])
def test_sharded_worlds_equal_single_envs(env_id: str, monkeypatch: pytest.MonkeyPatch) -> None:
    """Scenes spread over several PyBullet worlds (one scene each here) step as single envs."""
    monkeypatch.setattr(batch_module, "SHARD_OBJECTS", 1)
    vec = make_vec(env_id, 3)
    try:
        assert len(vec.unwrapped._batch.worlds) == 3
    finally:
        vec.close()
    n, steps = SIZES.get(env_id, (3, 120))
    assert run_pair(env_id, n, steps, max_episode_steps=30) >= 2


def test_scenes_per_world() -> None:
    assert batch_module.scenes_per_world(64, 1) == 8  # 8 objects per world
    assert batch_module.scenes_per_world(8, 7) == 1
    assert batch_module.scenes_per_world(8, 3) == 2
    assert batch_module.scenes_per_world(256, 7) == 11  # at most MAX_WORLDS (24) worlds
    assert batch_module.scenes_per_world(4, 40) == 1


@pytest.mark.parametrize("env_id", ["SGCRod-v1", "SGCThreeRods-v2"])
def test_small_batches_step_each_sub_env(env_id: str, monkeypatch: pytest.MonkeyPatch) -> None:
    """Below FAST_MIN_ENVS the sub-envs step by their own code (the goal env always does)."""
    monkeypatch.setattr(batch_module, "FAST_MIN_ENVS", 8)
    vec = make_vec(env_id, 2)
    try:
        assert vec.unwrapped._batch.fast is None
    finally:
        vec.close()
    assert run_pair(env_id, 2, 45, max_episode_steps=20) >= 2


@pytest.mark.parametrize("env_id", ["SGCRod-v1", "SGCThreeRods-v2"])
def test_goal_switches_measured_on_arrays_equal_single_envs(
    env_id: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Sub-envs whose goals switch are measured again one by one on floats, or, when many
    switch at once, by one pass on arrays: forced here, the same bits."""
    monkeypatch.setattr(task_module, "SCALAR_MEASURE_ROWS", 0)
    assert run_pair(env_id, 2, 90, "expert", max_episode_steps=40) >= 2
