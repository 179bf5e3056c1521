"""The environments: checkers, determinism, vectorisation, pickling, physics facts, contracts."""

from __future__ import annotations

import math
import pickle
import warnings

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env
from stable_baselines3.common.env_checker import check_env as sb3_check_env

import sgc_env
from sgc_env.envs import GoalEvent, SGCEnv, StepInfo
from sgc_env.observation import BASE_BLOCK_SIZE, RESIDUAL_FIELDS, float32_residuals
from sgc_env.scenario import (
    Body,
    Goal,
    Scenario,
    ScenarioError,
    load_scenario,
    resolve_scenario,
)


def rollout(env: gym.Env, seed: int, steps: int) -> list[np.ndarray]:
    obs, _ = env.reset(seed=seed)
    env.action_space.seed(seed)
    out = [obs]
    for _ in range(steps):
        obs, reward, terminated, truncated, _ = env.step(env.action_space.sample())
        out.append(np.append(obs, reward))
        if terminated or truncated:
            obs, _ = env.reset()
            out.append(obs)
    return out


@pytest.mark.parametrize("env_id", sgc_env.ENV_IDS)
def test_checkers_pass_with_warnings_as_errors(env_id):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        env = gym.make(env_id)
        check_env(env.unwrapped)
        env.close()
        env = gym.make(env_id)
        sb3_check_env(env.unwrapped)
        env.close()


@pytest.mark.parametrize("env_id", ["SGCPoint-v1", "SGCRod-v1", "SGCThreeRods-v2"])
def test_same_seed_same_rollout_bitwise(env_id):
    a, b = gym.make(env_id), gym.make(env_id)
    ra, rb = rollout(a, 7, 150), rollout(b, 7, 150)
    assert len(ra) == len(rb)
    for x, y in zip(ra, rb, strict=True):
        assert x.tobytes() == y.tobytes()


def test_seeded_then_plain_reset_is_deterministic():
    a, b = gym.make("SGCPoint-v1"), gym.make("SGCPoint-v1")
    a.reset(seed=11)
    b.reset(seed=11)
    oa, _ = a.reset()
    ob, _ = b.reset()
    assert oa.tobytes() == ob.tobytes()
    assert a.unwrapped.scenario == b.unwrapped.scenario


def test_random_scenario_changes_with_reset():
    env = gym.make("SGCPoint-v1")
    env.reset(seed=1)
    first = env.unwrapped.scenario
    env.reset()
    assert env.unwrapped.scenario != first
    # the action scale is not observed, so it must stay fixed between episodes
    assert env.unwrapped.scenario.bodies[0].force_limit == first.bodies[0].force_limit


@pytest.mark.parametrize("mode", ["sync", "async"])
def test_make_vec(mode):
    envs = gym.make_vec("SGCRod-v1", num_envs=2, vectorization_mode=mode)
    obs, _ = envs.reset(seed=3)
    assert obs.shape == (2, envs.single_observation_space.shape[0])
    for _ in range(5):
        obs, reward, term, trunc, info = envs.step(envs.action_space.sample())
    assert obs.dtype == np.float32 and reward.shape == (2,)
    envs.close()


@pytest.mark.parametrize("env_id", ["SGCRod-v1", "SGCIntercept-v1", "SGCPointGoal-v1"])
def test_pickle_continues_identically(env_id):
    env = gym.make(env_id).unwrapped
    env.reset(seed=5)
    env.action_space.seed(5)
    for _ in range(10):
        env.step(env.action_space.sample())
    clone = pickle.loads(pickle.dumps(env))
    actions = [env.action_space.sample() for _ in range(20)]
    for a in actions:
        o1, r1, *_ = env.step(a)
        o2, r2, *_ = clone.step(a)
        if isinstance(o1, dict):
            o1, o2 = np.concatenate(list(o1.values())), np.concatenate(list(o2.values()))
        assert o1.tobytes() == o2.tobytes() and r1 == r2
    env.reset()
    clone.reset()
    assert env.unwrapped.scenario == clone.unwrapped.scenario
    clone.close()


def test_save_restore_state():
    env = gym.make("SGCRod-v1").unwrapped
    env.reset(seed=2)
    env.action_space.seed(2)
    for _ in range(5):
        env.step(env.action_space.sample() * 0.1)
    saved = env.save_state()
    actions = [env.action_space.sample() * 0.1 for _ in range(40)]
    first = [env.step(a)[0] for a in actions]
    env.restore_state(saved)
    second = [env.step(a)[0] for a in actions]
    for x, y in zip(first, second, strict=True):
        assert x.tobytes() == y.tobytes()


def coasting_scenario(velocity=(1.0, 0.0, 0.0), angular=(0.0, 0.0, 0.0), shape="sphere"):
    size = (0.05,) if shape == "sphere" else (0.6, 0.03)
    body = Body(
        "b", shape=shape, size=size, position=(0.0, 0.0, 1.0), linear_velocity=velocity,
        angular_velocity=angular, goals=(Goal(nail=(1.0, 0.0, 1.0), time=1.0),),
    )  # fmt: skip
    return Scenario(bodies=(body,), gravity=(0.0, 0.0, 0.0), margin=0.0)


def test_damping_is_off_body_coasts_at_constant_speed():
    env = SGCEnv(coasting_scenario(angular=(0.0, 0.0, 3.0), shape="rod"))
    env.reset()
    for _ in range(60):
        _, _, terminated, truncated, info = env.step(np.zeros(6, np.float32))
    assert info["time"] == pytest.approx(1.0)
    assert info["body_velocity"][0].tolist() == [1.0, 0.0, 0.0]
    assert info["body_angular_velocity"][0].tolist() == [0.0, 0.0, 3.0]
    assert info["body_position"][0][0] == pytest.approx(1.0, abs=1e-12)
    assert truncated and not terminated


def test_force_acts_at_centre_of_mass_without_spin():
    env = SGCEnv(coasting_scenario(velocity=(0.3, -0.2, 0.1), shape="rod"))
    env.reset()
    for _ in range(30):
        _, _, _, _, info = env.step(np.array([0.5, -0.3, 0.8, 0, 0, 0], np.float32))
    assert np.max(np.abs(info["body_angular_velocity"])) < 1e-12


@pytest.mark.parametrize("shape", ["rod", "box"])
def test_unit_torque_action_gives_the_same_angular_acceleration_in_every_direction(shape):
    tilt = (0.2, -0.4, 0.3, 0.8)
    tilt = tuple(np.divide(tilt, np.linalg.norm(tilt)))
    body = Body(
        "b", shape=shape, size=(0.6, 0.03) if shape == "rod" else (0.3, 0.1, 0.02),
        position=(0.0, 0.0, 1.0), orientation=tilt, goals=(Goal(nail=(1.0, 0.0, 1.0), time=1.0),),
    )  # fmt: skip
    env = SGCEnv(Scenario(bodies=(body,), gravity=(0.0, 0.0, 0.0), margin=0.0))
    inertia = env.body_inertia[0]
    assert env.torque_scale[0] == pytest.approx(body.torque_limit * inertia / inertia.max())
    rm = np.array(sgc_env.simulator.pybullet.getMatrixFromQuaternion(tilt)).reshape(3, 3)
    expected = body.torque_limit / inertia.max() * env.dt
    # the body's own axes (its thin axis included) and two world directions
    oblique = np.array((0.3, -0.5, 0.8)) / np.linalg.norm((0.3, -0.5, 0.8))
    for direction in [*rm.T, (1.0, 0.0, 0.0), oblique]:
        env.reset()
        _, _, _, _, info = env.step(np.concatenate([np.zeros(3), -np.asarray(direction)]))
        omega = info["body_angular_velocity"][0]
        # one substep's rotation moves the axes a little; from rest the tick is the same for all
        assert omega == pytest.approx(-expected * np.asarray(direction), abs=2e-2 * expected)
        scaled = rm @ (env.torque_scale[0] * (rm.T @ -np.asarray(direction)))
        assert info["torque"][0] == pytest.approx(scaled)


def test_gravity_is_on_by_default_and_not_compensated():
    s = load_scenario("point_three_goals")
    env = SGCEnv(s)
    env.reset()
    _, _, _, _, info = env.step(np.zeros(3, np.float32))
    assert info["body_velocity"][0][2] == pytest.approx(-9.81 / 60)


def test_control_frequency_must_divide_sim_frequency():
    with pytest.raises(ValueError, match="integer multiple"):
        SGCEnv("point_three_goals", control_frequency=70)
    env = SGCEnv("point_three_goals", control_frequency=120)
    assert env.substeps == 2


def test_observation_contract_fields():
    env = SGCEnv("rod_basic", observation="planner")
    obs, info = env.reset()
    lay = env.layout
    assert obs.shape == (lay.size,) and obs.dtype == np.float32
    s = env.scenario
    nail = np.array(s.bodies[0].goals[0].nail)
    point = np.array(info["point_position"][0])
    np.testing.assert_allclose(
        obs[lay.body_slice(0, "position_deviation")], point - nail, atol=1e-6
    )
    np.testing.assert_allclose(obs[lay.body_slice(0, "point_offset")], [0, 0, 0.3], atol=1e-7)
    assert obs[lay.body_slice(0, "position_time_left")][0] == pytest.approx(0.5)
    assert obs[lay.body_slice(0, "position_course_duration")][0] == pytest.approx(0.5)
    np.testing.assert_allclose(
        obs[lay.body_slice(0, "position_next_start")],
        nail - np.array(s.bodies[0].goals[1].nail),
        atol=1e-6,
    )
    assert obs[lay.body_slice(0, "position_flags")].tolist() == [1.0, 0.0]
    assert obs[lay.body_slice(0, "orientation_flags")].tolist() == [1.0, 0.0]
    assert obs[lay.global_slice("time")][0] == 0.0


def test_residuals_recover_doubles_and_observations_are_not_reused():
    env = SGCEnv("three_rods", observation="planner")
    obs, _ = env.reset()
    lay = env.layout
    assert RESIDUAL_FIELDS == (  # the order SGCEnv._observe writes the residual sources in
        "position_deviation", "point_velocity", "orientation", "angular_velocity",
        "linear_velocity", "orientation_deviation", "position_time_left",
        "orientation_time_left", "point_offset",
    )  # fmt: skip
    mask = lay.residual_mask
    assert mask.sum() == lay.n_bodies * (lay.body_block_size - BASE_BLOCK_SIZE)
    assert all(mask[lay.body_slice(i, "point_offset_residual")].all() for i in range(lay.n_bodies))
    assert not mask[lay.global_slice("time")].any()
    rng = np.random.default_rng(0)
    kept = [(obs, obs.copy())]
    for _ in range(30):
        obs, _, _, _, info = env.step(rng.uniform(-0.2, 0.2, env.action_space.shape))
        kept.append((obs, obs.copy()))
        for i in range(lay.n_bodies):
            for field, exact in (
                ("position_deviation", info["position_deviation"][i]),
                ("point_velocity", info["point_velocity"][i]),
                ("orientation", info["body_orientation"][i]),
                ("orientation_deviation", info["orientation_deviation"][i]),
            ):
                value = obs[lay.body_slice(i, field)].astype(np.float64)
                value += obs[lay.body_slice(i, f"{field}_residual")]
                np.testing.assert_allclose(value, exact, rtol=1e-14, atol=1e-15)
    assert all(np.array_equal(returned, copy) for returned, copy in kept)


@pytest.mark.parametrize("extremes", [False, True])
def test_float32_residuals_are_what_a_float32_cast_loses(extremes):
    rng = np.random.default_rng(3)
    values = (rng.normal(size=200) * 10.0 ** rng.integers(-40, 38, size=200)).tolist()
    values += [0.0, -0.0, 1e-320, math.inf, -math.inf, math.nan]
    if extremes:  # too large for float32: the struct path overflows, numpy rounds to inf
        values += [3.5e38, -1e39, 1e300]
    full = np.array(values)
    with np.errstate(over="ignore", invalid="ignore"):
        expected = full - full.astype(np.float32).astype(np.float64)
    got = np.array(float32_residuals(values))
    assert got.tobytes() == expected.tobytes()


def test_goal_ticks_advance_goals_and_report_errors():
    env = SGCEnv("point_three_goals", observation="planner")
    obs, _ = env.reset()
    lay = env.layout
    events = []
    steps = 0
    truncated = False
    while not truncated:
        obs, _, terminated, truncated, info = env.step(np.array([0, 0, 9.81 / 60], np.float32))
        steps += 1
        events += info.get("goal_reached", [])
        assert not terminated
        assert set(info) - {"goal_reached"} == StepInfo.__required_keys__
        assert set(info) - StepInfo.__required_keys__ <= StepInfo.__optional_keys__
    assert all(set(e) == GoalEvent.__required_keys__ for e in events)
    assert steps == 90 + 15  # last goal at 1.5 s, margin 0.25 s, 60 Hz
    assert [e["goal"] for e in events] == [0, 1, 2]
    assert [round(e["time"] * 60) for e in events] == [30, 58, 90]
    assert all(e["orientation_error"] is None and e["position_error"] > 0 for e in events)
    assert obs[lay.body_slice(0, "position_flags")].tolist() == [1.0, 1.0]
    assert obs[lay.body_slice(0, "position_time_left")][0] == pytest.approx(-0.25, abs=1e-6)
    end_v = obs[lay.body_slice(0, "position_end_velocity")]
    g = env.scenario.bodies[0].goals
    expected = (np.array(g[2].nail) - np.array(g[1].nail)) / (g[2].time - g[1].time)
    np.testing.assert_allclose(end_v, expected, rtol=1e-6)


def _somersault_env(time: float, check_plan: bool = True) -> SGCEnv:
    body = Body(
        "rod", shape="rod", size=(0.6, 0.03), position=(0.0, 0.0, 1.0),
        angular_velocity=(2.0 * math.pi, 0.0, 0.0),
        goals=(Goal(relative_rotation=(2.0 * math.pi, 0.0, 0.0), time=time),),
    )  # fmt: skip
    scenario = Scenario(bodies=(body,), gravity=(0, 0, 0), margin=0.0)
    return SGCEnv(resolve_scenario(scenario, check_plan=check_plan), observation="planner")


def test_somersault_is_split_into_courses_tracked_continuously():
    # A deviation of 2 pi sits on the singular shell of the rotation vector, so the env splits
    # the somersault into courses; entered and left at its own pace, the smooth split is 15
    # equal courses of 4 ticks (about pi / 8 each, at least 4 ticks); the rotation still left
    # (phi plus the courses not started yet) must fall smoothly from -2 pi to 0.
    env = _somersault_env(1.0)
    obs, _ = env.reset()
    sl = env.layout.body_slice(0, "orientation_deviation")
    piece = -2.0 * math.pi / 15.0
    np.testing.assert_allclose(obs[sl], [piece, 0, 0], atol=1e-6)
    np.testing.assert_allclose(
        obs[env.layout.body_slice(0, "orientation_course_start")], [piece, 0, 0], rtol=1e-6
    )
    remaining, events = [], []
    for k in range(60):
        obs, *_, info = env.step(np.zeros(6, np.float32))
        courses_left = 14 - min(14, (k + 1) // 4)
        remaining.append(obs[sl][0] + courses_left * piece)
        events += info.get("goal_reached", [])
    # coasting at 2 pi rad/s for 1 s completes the somersault
    assert np.all(np.diff(remaining) > 0)
    assert remaining[-1] == pytest.approx(0.0, abs=1e-6)
    assert [e["goal"] for e in events] == [0]
    assert events[0]["orientation_error"] < 1e-6


def test_somersault_without_enough_ticks_is_rejected():
    # The plan check splits the somersault on the env's ticks too, so it refuses it first.
    with pytest.raises(ValueError, match=r"bodies\[0\]\.goals.*rotation of 6.28.*3 courses"):
        _somersault_env(2.0 / 60.0)
    # Without the plan check the env's own course split still refuses it.
    with pytest.raises(ValueError, match=r"rod.goals\[0\].*relative rotation of 6.28.*3 courses"):
        _somersault_env(2.0 / 60.0, check_plan=False)


def test_workspace_exit_terminates():
    body = Body("b", position=(0.0, 0.0, 0.0), linear_velocity=(30.0, 0.0, 0.0),
                goals=(Goal(nail=(0.5, 0.0, 0.0), time=1.0),))  # fmt: skip
    s = Scenario(bodies=(body,), gravity=(0, 0, 0), workspace=((-1, -1, -1), (1, 1, 1)))
    with pytest.raises(ScenarioError, match="force of 11"):  # the plan check sees it coming
        resolve_scenario(s)
    env = SGCEnv(resolve_scenario(s, check_plan=False))
    env.reset()
    for _ in range(10):
        _, _, terminated, truncated, _ = env.step(np.zeros(3, np.float32))
        if terminated:
            break
    assert terminated and not truncated


def test_scenario_swap_via_reset_options():
    env = SGCEnv("point_three_goals")
    env.reset(options={"scenario": "intercept"})
    assert env.scenario.name == "intercept"
    assert env.scenario.props[0].name == "fish"
    with pytest.raises(ValueError, match="bodies"):
        env.reset(options={"scenario": "three_rods"})


def test_intercept_target_moves_kinematically():
    env = SGCEnv("intercept")
    env.reset()
    uid = env.sim.bodies["fish"].uid
    for _ in range(60):
        env.step(np.zeros(3, np.float32))
    pos = sgc_env.simulator.pybullet.getBasePositionAndOrientation(
        uid, physicsClientId=env.sim.client
    )[0]
    np.testing.assert_allclose(pos, env.scenario.props[0].position_at(1.0), atol=1e-12)


def test_goal_env_compute_reward_is_vectorised():
    env = gym.make("SGCPointGoal-v1").unwrapped
    obs, _ = env.reset(seed=0)
    a = np.stack([obs["desired_goal"], obs["achieved_goal"]])
    d = np.stack([obs["desired_goal"], obs["desired_goal"]])
    assert env.compute_reward(a, d, [{}, {}]).tolist() == [0.0, -1.0]


def test_goal_env_charges_the_steps_a_failure_leaves():
    env = gym.make("SGCPointGoal-v1")
    env.reset(seed=0)
    base = env.unwrapped
    terminated = False
    while not terminated:
        obs, reward, terminated, truncated, info = env.step(np.ones(3))
        assert not truncated
    left = base.max_steps - base._tick
    assert left > 0 and info["failure_charge"] == left
    assert reward == -1.0 - left
    # HER recomputes rewards with the stored infos: the charge survives relabelling
    goal = obs["achieved_goal"][None]
    relabelled = base.compute_reward(goal, goal, [info])
    assert relabelled.tolist() == [-float(left)]
    with pytest.raises(ValueError, match="reward modes apply to SGCEnv"):
        gym.make("SGCPointGoal-v1", reward="sparse")


def test_goal_env_with_her():
    from stable_baselines3 import SAC, HerReplayBuffer

    env = gym.make("SGCPointGoal-v1")
    model = SAC(
        "MultiInputPolicy", env, replay_buffer_class=HerReplayBuffer, learning_starts=300,
        batch_size=32,
        policy_kwargs={"net_arch": [16]}, seed=0,
    )  # fmt: skip
    model.learn(330)
    # HER relabels desired goals with achieved ones; every relabelled reward must be the env's
    # own compute_reward(next achieved, desired), and relabelling must create successes.
    batch = model.replay_buffer.sample(2000)
    achieved = batch.next_observations["achieved_goal"].numpy()
    desired = batch.observations["desired_goal"].numpy()
    expected = env.unwrapped.compute_reward(achieved, desired, [{}] * len(desired))
    rewards = batch.rewards.numpy().ravel()
    # A failure's transition also carries the charge for the steps it left (its stored info's
    # failure_charge, which the empty infos here do not have); those are terminal.
    charged = rewards < -1.0
    np.testing.assert_array_equal(rewards[~charged], expected[~charged])
    assert (batch.dones.numpy().ravel()[charged] == 1.0).all()
    assert model.num_timesteps == 330 and (rewards == 0.0).any() and (rewards == -1.0).any()


def test_close_disconnects():
    env = SGCEnv("point_three_goals")
    client = env.sim.client
    env.close()
    assert not sgc_env.simulator.pybullet.isConnected(physicsClientId=client)


def test_spin_clamp_is_flagged_not_terminal():
    env = SGCEnv(coasting_scenario(velocity=(0.0, 0.0, 0.0), angular=(0, 0, 98.9), shape="rod"))
    env.reset()
    _, _, terminated, _, info = env.step(np.array([0, 0, 0, 0, 0, 1], np.float32))
    assert info["spin_clamped"] and not terminated


def test_goals_of_every_body_are_reported_when_another_body_is_done():
    a = Body("a", position=(0.0, 0.0, 1.0), goals=(Goal(nail=(0.1, 0.0, 1.0), time=0.5),))
    b = Body(
        "b", position=(0.0, 1.0, 1.0),
        goals=(Goal(nail=(0.1, 1.0, 1.0), time=0.25), Goal(nail=(0.2, 1.0, 1.0), time=1.0)),
    )  # fmt: skip
    env = SGCEnv(Scenario(bodies=(a, b), gravity=(0, 0, 0), margin=0.0))
    env.reset()
    events, truncated = [], False
    while not truncated:
        _, _, _, truncated, info = env.step(np.zeros(6, np.float32))
        events += [
            (e["body"], e["goal"], round(e["time"] * 60)) for e in info.get("goal_reached", [])
        ]
    assert events == [(1, 0, 15), (0, 0, 30), (1, 1, 60)]


def test_one_env_id_check_names_the_field_and_the_ids():
    assert sgc_env.check_env_id("SGCPoint-v1") == "SGCPoint-v1"
    with pytest.raises(ValueError, match=r"^env: unknown environment 'Nope-v0'; SGC ids: \['SGCP"):
        sgc_env.check_env_id("Nope-v0", "env")
    with pytest.raises(ValueError, match="^env_id: unknown environment 3;"):
        sgc_env.check_env_id(3)


def _track_score(obs: np.ndarray, lay, track: str, floor: float) -> float:
    """``1 / (1 + |D - D_sched| / L)`` of one track, from the planner's view."""
    d = obs[lay.body_slice(0, f"{track}_deviation")].astype(np.float64)
    left = float(obs[lay.body_slice(0, f"{track}_time_left")][0])
    start = obs[lay.body_slice(0, f"{track}_course_start")].astype(np.float64)
    duration = float(obs[lay.body_slice(0, f"{track}_course_duration")][0])
    end = obs[lay.body_slice(0, f"{track}_end_velocity")].astype(np.float64)
    schedule = start * left / duration if left >= 0 else -end * left
    return 1.0 / (1.0 + np.linalg.norm(d - schedule) / max(np.linalg.norm(start), floor))


def test_tracking_reward_is_its_documented_formula():
    """r = sum_tracks 1 / (1 + |D - D_sched| / L) + 0.01 (1 - mean(a^2)) + goal bonuses, for one
    rod (L: the current course's start deviation, floored at 0.1 m and 0.5 rad; D_sched =
    D_i(0) time_left / T_i, after the last goal -v_end time_left), read off the planner's view."""
    env = gym.make("SGCRod-v1", observation="planner")
    obs, _ = env.reset(seed=3)
    lay = env.unwrapped.layout
    rng = np.random.default_rng(0)
    bonus_ticks = 0
    for _ in range(150):
        a = rng.uniform(-1, 1, env.action_space.shape).astype(np.float32)
        obs, reward, terminated, truncated, info = env.step(a)
        expected = (
            _track_score(obs, lay, "position", 0.1) + _track_score(obs, lay, "orientation", 0.5)
            + 0.01 - 0.01 * np.mean(a.astype(np.float64) ** 2)
        )  # fmt: skip
        for ev in info.get("goal_reached", []):
            bonus_ticks += 1
            if ev["position_error"] is not None:
                expected += math.exp(-ev["position_error"] / 0.01)
            if ev["orientation_error"] is not None:
                expected += math.exp(-ev["orientation_error"] / 0.02)
        assert reward == pytest.approx(expected, rel=1e-4, abs=1e-6)
        if terminated or truncated:
            break
    assert bonus_ticks > 0
    env.close()


def test_the_suite_closes_the_envs_a_test_leaves_open(close_envs):
    from tests.conftest import closing_every_env

    with closing_every_env() as made:
        left_open = gym.make("SGCPoint-v1")
        closed = SGCEnv("point_three_goals")
        closed.close()
        client = left_open.unwrapped.sim.client
        assert sgc_env.simulator.pybullet.isConnected(physicsClientId=client)
    assert set(made) == {left_open.unwrapped, closed}
    assert left_open.unwrapped.sim is None and left_open.unwrapped._closed
    assert not sgc_env.simulator.pybullet.isConnected(physicsClientId=client)
    assert set(close_envs) >= set(made)  # nested blocks: the autouse fixture saw them too


def test_sim_frequency_over_the_cap_is_refused_by_the_env_itself() -> None:
    """Code that calls gym.make directly meets the same cap as --env-kwargs and recipes."""
    from sgc_env.scenario.caps import cap

    limit = cap("sim_frequency")
    with pytest.raises(ValueError, match="over the cap"):
        gym.make("SGCPoint-v1", sim_frequency=limit - limit % 60 + 60)
    env = gym.make("SGCPoint-v1", sim_frequency=limit - limit % 60)
    assert env.unwrapped.substeps == (limit - limit % 60) // 60
    env.close()
