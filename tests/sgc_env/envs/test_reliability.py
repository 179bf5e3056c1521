"""Issue 12: transactional scenario swaps, simulator lifetime, bounded work, reported errors."""

from __future__ import annotations

import gc
import math
import time

import gymnasium as gym
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import sgc_env  # noqa: F401  (registers the ids)
from sgc_env.envs import SGCEnv
from sgc_env.envs.props import CHUNK
from sgc_env.paper.orientation import MAX_RELATIVE_ROTATION
from sgc_env.paper.plan import BodyState, OrientationGoal, plan_body
from sgc_env.scenario import LIMITS, Body, Goal, Prop, Scenario, resolve_scenario
from sgc_env.simulator import connected_clients


@pytest.fixture(autouse=True)
def close_envs():
    """Replaces conftest's fixture of that name in this module: it keeps every env alive to
    close it after the test, and these tests are about envs nobody closes or keeps."""
    yield []


def rollout(env: SGCEnv, seed: int, steps: int = 40) -> list[bytes]:
    """Observations and rewards of a seeded random rollout, as bytes."""
    obs, _ = env.reset(seed=seed)
    rng = np.random.default_rng(seed)
    out = [obs.tobytes()]
    for _ in range(steps):
        obs, reward, terminated, truncated, _ = env.step(
            rng.uniform(-1, 1, env.action_space.shape).astype(np.float32)
        )
        out += [obs.tobytes(), np.float64(reward).tobytes()]
        if terminated or truncated:
            break
    return out


def somersault(time: float) -> Scenario:
    """A rod asked for a full turn in ``time``: the env's course split needs three ticks."""
    body = Body(
        "rod", shape="rod", size=(0.6, 0.03), position=(0.0, 0.0, 1.0),
        goals=(Goal(relative_rotation=(2.0 * math.pi, 0.0, 0.0), time=time),),
    )  # fmt: skip
    return resolve_scenario(Scenario(bodies=(body,), gravity=(0, 0, 0)), check_plan=False)


# ---------------------------------------------------------------- 1: transactional swaps


def test_rejected_swap_leaves_the_env_exactly_as_it_was():
    env = SGCEnv("rod_basic")
    before = rollout(env, seed=3)
    scenario = env.scenario
    with pytest.raises(ValueError, match="3 courses"):  # fails while compiling tracks
        env.reset(seed=5, options={"scenario": somersault(2.0 / 60.0)})
    assert env.scenario is scenario
    assert rollout(env, seed=3) == before
    env.close()


def test_rejected_swap_keeps_the_harness_scoring_the_old_goals():
    from baselines import SGCExpert
    from baselines.evaluation.harness import run_episode

    env = SGCEnv("rod_basic")
    with pytest.raises(ValueError):
        env.reset(options={"scenario": somersault(2.0 / 60.0)})
    card = run_episode(SGCExpert(env), env, seed=0).card
    assert card["goals_met"] == card["n_goals"] == len(env.scenario.bodies[0].goals)
    env.close()


def test_rejected_construction_leaves_no_client():
    gc.collect()
    before = connected_clients()
    for _ in range(5):
        with pytest.raises(ValueError, match="3 courses"):
            SGCEnv(somersault(2.0 / 60.0))
        with pytest.raises(ValueError, match="sim_frequency"):
            gym.make("SGCRod-v1", sim_frequency=250)
    assert connected_clients() == before


def test_failure_after_the_client_exists_leaks_nothing(monkeypatch):
    from sgc_env.simulator import Simulator

    def broken(self, *args, **kwargs):
        raise RuntimeError("no body today")

    monkeypatch.setattr(Simulator, "add_body", broken)
    gc.collect()
    before = connected_clients()
    for _ in range(5):
        with pytest.raises(RuntimeError, match="no body today"):
            gym.make("SGCRod-v1")
    assert connected_clients() == before  # closed at once, not left to the garbage collector


# ---------------------------------------------------------------- 2: simulator lifetime


def _rss_mb() -> float:
    with open("/proc/self/status") as fh:
        for line in fh:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024
    raise RuntimeError("no VmRSS in /proc/self/status")


def test_300_unclosed_envs_keep_memory_flat():
    gc.collect()
    clients = connected_clients()
    start = _rss_mb()
    for _ in range(300):
        env = gym.make("SGCRod-v1")
        env.reset(seed=0)
        env.step(env.action_space.sample())
        del env  # never closed: the finaliser must free the PyBullet client
    gc.collect()
    growth = _rss_mb() - start
    assert growth < 500, f"RSS grew by {growth:.0f} MB"
    assert connected_clients() == clients


def test_closed_env_says_so():
    env = SGCEnv("point_three_goals")
    env.close()
    env.close()  # idempotent
    for call in (
        lambda: env.step(np.zeros(3, np.float32)),
        lambda: env.reset(),
        env.save_state,
        lambda: env.apply_impulse(0, (1.0, 0.0, 0.0)),
    ):
        with pytest.raises(RuntimeError, match="this SGCEnv is closed"):
            call()


def test_saved_states_can_be_freed_and_are_freed_when_dropped():
    env = SGCEnv("point_three_goals")
    env.reset(seed=0)
    state = env.save_state()
    env.step(np.ones(3, np.float32))
    obs = env.restore_state(state)
    assert state.alive
    env.free_state(state)
    assert not state.alive
    with pytest.raises(ValueError, match="was freed"):
        env.restore_state(state)
    state.free()  # a second free does nothing
    # Dropped snapshots free themselves: 2000 of them (~100 KB each) stay far below 200 MB.
    gc.collect()
    start = _rss_mb()
    for _ in range(2000):
        env.save_state()
    gc.collect()
    assert _rss_mb() - start < 100
    kept = env.save_state()
    env.close()
    assert not kept.alive and obs.shape == env.observation_space.shape


# ---------------------------------------------------------------- 4: bounded work


def test_plan_body_refuses_a_million_radians_at_once():
    started = time.perf_counter()
    with pytest.raises(ValueError, match="orientation goal 0: relative rotation of 1e\\+06"):
        plan_body(
            BodyState(np.zeros(3), np.array([0.0, 0.0, 0.0, 1.0])),
            [],
            [OrientationGoal(1.0, relative_rotation=np.array([1e6, 0.0, 0.0]))],
        )
    assert time.perf_counter() - started < 1.0
    assert LIMITS["relative_rotation"][1] == MAX_RELATIVE_ROTATION


def test_long_episode_with_a_moving_prop_is_computed_in_chunks():
    body = Body("b", position=(0.0, 0.0, 1.0), goals=(Goal(nail=(0.0, 0.0, 1.0), time=1600.0),))
    prop = Prop("p", position=(0.0, 0.0, 0.0), velocity=(0.001, 0.0, 0.0))
    s = resolve_scenario(Scenario(bodies=(body,), props=(prop,), gravity=(0, 0, 0)))
    env = SGCEnv(s)
    paths = env._props
    far = paths.last - 5
    assert paths.at(far)[0] == [far / env.sim_frequency * 0.001, 0.0, 0.0]
    assert len(paths._chunk) <= CHUNK
    env.close()


# ---------------------------------------------------------------- 6: reported errors


def test_goal_event_reports_the_true_angle():
    # The rod does not turn (no torque): at the goal tick it is 4 rad the short way round
    # from the goal unwrapped, 2 pi - 4 rad in truth.
    body = Body("rod", shape="rod", size=(0.6, 0.03), position=(0.0, 0.0, 1.0),
                goals=(Goal(relative_rotation=(4.0, 0.0, 0.0), time=0.5),))  # fmt: skip
    s = resolve_scenario(Scenario(bodies=(body,), gravity=(0, 0, 0)), check_plan=False)
    env = SGCEnv(s)
    env.reset(seed=0)
    events = []
    for _ in range(30):
        _, _, _, _, info = env.step(np.zeros(6, np.float32))
        events += info.get("goal_reached", [])
    (event,) = events
    truth = (Rotation.from_rotvec([4.0, 0.0, 0.0]).inv()).magnitude()
    assert event["orientation_error"] == pytest.approx(truth, abs=1e-9)
    assert event["orientation_error"] == pytest.approx(2 * math.pi - 4.0, abs=1e-9)
    env.close()


def test_huge_finite_actions_are_clipped_not_rejected():
    env = SGCEnv("point_three_goals")
    env.reset(seed=0)
    big = env.step(np.full(3, 1e308))
    env.reset(seed=0)
    one = env.step(np.ones(3))
    assert big[0].tobytes() == one[0].tobytes() and big[1] == one[1]
    for bad in ([math.nan, 0, 0], [math.inf, 0, 0], [0, -math.inf, 0], [1e308, math.nan, 0]):
        with pytest.raises(ValueError, match="non-finite"):
            env.step(np.array(bad))
    with pytest.raises(TypeError, match="real numbers, got dtype complex128"):
        env.step(np.array([1j, 0, 0]))
    with pytest.raises(TypeError, match="dtype"):
        env.step(["a", "b", "c"])
    env.close()
