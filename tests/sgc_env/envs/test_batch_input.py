"""Bad input to the batched env is refused with errors naming the sub-env; a failing sub-env
leaves the others alone; close() frees the PyBullet client and make/close cycles leak
nothing."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

from baselines import SGCExpert
from sgc_env.envs.vector import batch as batch_module
from sgc_env.envs.vector.batch import MAX_ENVS
from sgc_env.envs.vector.vector_env import SGCVectorEnv
from sgc_env.simulator import connected_clients


@pytest.fixture(autouse=True)
def _numpy_step_from_one_env(monkeypatch: pytest.MonkeyPatch) -> None:
    """Small batches here step by the numpy path, as batches of FAST_MIN_ENVS or more do."""
    monkeypatch.setattr(batch_module, "FAST_MIN_ENVS", 1)


def _rss_mb() -> float:
    pages = int(Path("/proc/self/statm").read_text().split()[1])
    return pages * 4096 / 2**20


@pytest.mark.parametrize("num_envs", [0, -1, MAX_ENVS + 1, 2.5, True, "4"])
def test_num_envs_out_of_range_is_refused(num_envs: object) -> None:
    before = len(connected_clients())
    with pytest.raises(ValueError, match="num_envs"):
        SGCVectorEnv(num_envs, scenario="point_three_goals")  # type: ignore[arg-type]
    assert len(connected_clients()) == before


def test_bad_actions_name_the_sub_env() -> None:
    vec = SGCVectorEnv(3, scenario="point_three_goals")
    vec.reset(seed=0)
    with pytest.raises(ValueError, match=r"actions have shape \(3, 4\), expected \(3, 3\)"):
        vec.step(np.zeros((3, 4), np.float32))
    with pytest.raises(ValueError, match="shape"):
        vec.step(np.zeros(3, np.float32))
    with pytest.raises(TypeError, match="sub-env 0: action must hold real numbers"):
        vec.step(np.full((3, 3), "x"))
    for bad in (np.nan, np.inf, -np.inf):
        actions = np.zeros((3, 3), np.float32)
        actions[2, 1] = bad
        with pytest.raises(ValueError, match="sub-env 2: action contains non-finite"):
            vec.step(actions)
    # a refused step changed nothing: the next good step is the first one
    obs, *_ = vec.step(np.zeros((3, 3), np.float32))
    single = gym.make("SGCPoint-v1", scenario="point_three_goals")
    single.reset(seed=1)
    assert np.array_equal(obs[1], single.step(np.zeros(3, np.float32))[0])
    single.close()
    with pytest.raises(ValueError, match="seed: 2 seeds for 3 sub-envs"):
        vec.reset(seed=[1, 2])
    with pytest.raises(ValueError, match="reset_mask"):
        vec.reset(options={"reset_mask": np.ones(2, bool)})
    vec.close()


def test_a_scenario_the_world_cannot_share_is_refused() -> None:
    vec = SGCVectorEnv(2, scenario="point_three_goals")
    vec.reset(seed=0)
    moon = replace(vec.envs[0].scenario, gravity=(0.0, 0.0, -1.62))
    with pytest.raises(ValueError, match="sub-env 0: scenario gravity .* one gravity"):
        vec.reset(options={"scenario": moon})
    vec.close()
    vec = SGCVectorEnv(2, scenario="intercept")
    scene = vec.envs[0].scenario  # its body collides; with a colliding prop, two objects do
    touching = replace(scene, props=tuple(replace(p, collisions=True) for p in scene.props))
    with pytest.raises(ValueError, match="sub-env 0: .* collide with each other"):
        vec.reset(options={"scenario": touching})
    with pytest.raises(ValueError, match="does not render"):
        SGCVectorEnv(2, scenario="point_three_goals", render_mode="rgb_array")
    with pytest.raises(NotImplementedError, match="shares its PyBullet client"):
        vec.envs[0].save_state()
    vec.close()


def test_a_failing_sub_env_leaves_the_others_alone() -> None:
    """Sub-env 0 thrusts out of the workspace and resets; sub-env 1 (on the same nails, the
    three-rod scene, whose bodies collide with each other) steps as a single env would."""
    vec = SGCVectorEnv(2, scenario="three_rods")
    single = gym.make("SGCThreeRods-v2")
    vec.reset(seed=0)
    o, _ = single.reset(seed=1)
    expert = SGCExpert(single)  # keeps sub-env 1 inside the workspace
    actions = np.ones((2, *vec.single_action_space.shape), np.float32)
    failed = 0
    for _ in range(60):
        actions[1] = expert.predict(o)[0]
        obs, rewards, terminated, truncated, _ = vec.step(actions)
        o, r, term, trunc, _ = single.step(actions[1])
        assert np.array_equal(obs[1], o) and rewards[1] == r and not terminated[1] and not term
        failed += int(terminated[0])
    assert failed >= 1
    vec.close()
    single.close()


def test_close_frees_the_client_and_cycles_leak_nothing() -> None:
    base = len(connected_clients())
    vec = gym.make_vec("SGCIntercept-v1", num_envs=4, vectorization_mode="vector_entry_point")
    vec.reset(seed=0)
    # one client for the bodies of four sub-envs, one (never stepped) for their props
    assert len(connected_clients()) == base + 2
    vec.close()
    assert len(connected_clients()) == base
    with pytest.raises(RuntimeError, match="closed"):
        vec.step(np.zeros((4, 3), np.float32))
    vec.close()  # idempotent
    _cycles(40, base)


def _cycles(n: int, base: int) -> None:
    """``n`` make/reset/step/close cycles: no client is left and RSS stays flat (the first
    cycles warm caches, so growth is measured from cycle 10)."""
    rss = 0.0
    for k in range(n):
        if k == 10:
            rss = _rss_mb()
        vec = SGCVectorEnv(2, scenario="intercept")
        vec.reset(seed=k)
        vec.step(np.zeros((2, *vec.single_action_space.shape), np.float32))
        vec.close()
        assert len(connected_clients()) == base
    assert _rss_mb() - rss < 20.0  # one leaked client alone holds ~30 MB


@pytest.mark.slow
def test_a_thousand_make_close_cycles_leak_nothing() -> None:
    """~40 ms each (PyBullet's connect), so slow."""
    _cycles(1000, len(connected_clients()))


def test_a_step_holds_the_collector_off_and_leaves_it_as_it_was(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The batched step runs with Python's cyclic collector off (its many short-lived lists
    trigger collections for nothing) and hands it back as found: on, off, or after an error."""
    import gc

    seen: list[bool] = []
    step = batch_module.BatchTask.step

    def watched(self: object, *args: object) -> object:
        seen.append(gc.isenabled())
        return step(self, *args)  # type: ignore[arg-type]

    monkeypatch.setattr(batch_module.BatchTask, "step", watched)
    env = gym.make_vec("SGCRod-v1", 12, vectorization_mode="vector_entry_point")
    env.reset(seed=0)
    assert gc.isenabled()
    env.step(np.zeros(env.action_space.shape, np.float32))
    assert seen == [False] and gc.isenabled()
    gc.disable()
    try:
        env.step(np.zeros(env.action_space.shape, np.float32))
        assert not gc.isenabled()
    finally:
        gc.enable()
    env.close()
    with pytest.raises(RuntimeError, match="inside"):
        with batch_module.collector_paused():
            raise RuntimeError("inside")
    assert gc.isenabled()
