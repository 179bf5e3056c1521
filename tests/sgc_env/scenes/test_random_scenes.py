"""The paper's scenes that vary: SGCInterceptRandom-v1 and SGCThreeRodsRandom-v3.

Every reset draws a new scene from the env's own ``np_random``; the expert meets every goal
exactly on every draw without needing an action beyond the limits; the spaces never change.
"""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import sgc_env
from baselines.controllers.expert import SGCExpert
from sgc_env.envs import SGCEnv
from sgc_env.paper.routing import resolve_goal_times
from sgc_env.scenario import resolve_scenario, scenario_from_dict
from sgc_env.scenario.demand import demand_bounds
from sgc_env.scenes import RandomInterceptConfig, RandomThreeRodsConfig, random_scenario
from sgc_env.scenes import intercept as random_intercept
from sgc_env.scenes import three_rods_random as random_three_rods
from sgc_env.scenes.three_rods import ROD_SPECS, build_three_rods

EXACT = 1e-9
DEMAND_SHARE = 0.8  # what both families allow the plan's bounds to use of each limit
RANDOM_IDS = ("SGCInterceptRandom-v1", "SGCThreeRodsRandom-v3")
FIXED_OF = {"SGCInterceptRandom-v1": "SGCIntercept-v1", "SGCThreeRodsRandom-v3": "SGCThreeRods-v2"}


def _expert_run(env, expert, seed: int) -> tuple[np.ndarray, list[float], bool]:
    """Per body, the largest |action| component, |force| and |torque| the expert applied;
    every goal error; whether the episode failed. The expert clips its action to the box, so a
    saturated component shows as exactly 1.0."""
    obs, _ = env.reset(seed=seed)
    base = env.unwrapped
    limits = np.array([[b.force_limit, b.torque_limit] for b in base.scenario.bodies])
    per = 6 if base.use_torque else 3
    peaks = np.zeros((len(limits), 3))
    errors, done, terminated = [], False, False
    while not done:
        action, _ = expert.predict(obs)
        a = action.reshape(len(limits), per)
        force = np.linalg.norm(a[:, :3], axis=1) * limits[:, 0]
        torque = np.linalg.norm(a[:, 3:], axis=1) * limits[:, 1]
        peaks = np.maximum(peaks, np.stack([np.abs(a).max(axis=1), force, torque], axis=1))
        obs, _, terminated, truncated, info = env.step(action)
        done = terminated or truncated
        for e in info.get("goal_reached", []):
            errors += [x for x in (e["position_error"], e["orientation_error"]) if x is not None]
    return peaks, errors, terminated


def _check_expert(env_id: str, seeds, *, against_plan: bool = False) -> float:
    env = gym.make(env_id)
    expert = SGCExpert(env)
    worst = 0.0
    for seed in seeds:
        peaks, errors, terminated = _expert_run(env, expert, seed)
        scenario = env.unwrapped.scenario
        goals = sum(len(b.goals) for b in scenario.bodies)
        assert not terminated, (env_id, seed)
        assert len(errors) >= goals, (env_id, seed, "a goal was not reported")
        assert max(errors) <= EXACT, (env_id, seed, max(errors))
        assert peaks[:, 0].max() < 1.0, (env_id, seed, "saturated")
        if against_plan:  # the margin the draws keep covers the expert's per-tick wrench
            bounds = np.array(demand_bounds(scenario))
            assert np.all(peaks[:, 1:] <= bounds / DEMAND_SHARE), (env_id, seed, peaks, bounds)
        worst = max(worst, float(peaks[:, 0].max()))
    env.close()
    return worst


@pytest.mark.parametrize(
    ("env_id", "seeds"), [("SGCInterceptRandom-v1", range(5)), ("SGCThreeRodsRandom-v3", [0])]
)
def test_expert_is_exact_within_the_limits_on_a_few_draws(env_id, seeds):
    _check_expert(env_id, [2000 + s for s in seeds], against_plan=True)


@pytest.mark.slow
@pytest.mark.parametrize("env_id", RANDOM_IDS)
def test_expert_is_exact_within_the_limits_on_100_draws(env_id):
    worst = _check_expert(env_id, range(100))
    print(f"{env_id}: largest |action| over 100 seeds {worst:.3f}")


@pytest.mark.parametrize("env_id", RANDOM_IDS)
def test_ids_are_registered_next_to_their_fixed_scenes(env_id):
    assert env_id in sgc_env.ENV_IDS and FIXED_OF[env_id] in sgc_env.ENV_IDS
    env, fixed = gym.make(env_id), gym.make(FIXED_OF[env_id])
    assert env.observation_space == fixed.observation_space
    assert env.action_space == fixed.action_space
    env.close()
    fixed.close()


@pytest.mark.parametrize("env_id", RANDOM_IDS)
def test_scenes_vary_with_the_seed_and_repeat_bit_for_bit(env_id):
    env = gym.make(env_id)
    base = env.unwrapped
    scenes, observations = [], []
    for seed in (5, 6, 5):
        obs, _ = env.reset(seed=seed)
        assert env.observation_space.contains(obs)
        scenes.append(base.scenario)
        observations.append(obs.tobytes())
    env.close()
    assert scenes[0] == scenes[2] and observations[0] == observations[2]
    assert scenes[0] != scenes[1]
    times = [[g.time for b in s.bodies for g in b.goals] for s in scenes]
    assert times[0] != times[1]


def test_interceptions_vary_in_meeting_time_start_and_target_path():
    rng = np.random.default_rng(1)
    scenes = [random_scenario(rng, "intercept") for _ in range(6)]
    meets = {s.bodies[0].goals[-1].time for s in scenes}
    starts = {s.bodies[0].position for s in scenes}
    paths = {s.props[0].waypoints for s in scenes}
    assert len(meets) > 1 and len(starts) == 6 and len(paths) == 6
    for s in scenes:
        bird, fish = s.bodies[0], s.props[0]
        meet = bird.goals[-1]
        assert np.allclose(meet.nail, fish.position_at(meet.time), atol=0, rtol=0)


def test_three_rod_scenes_vary_goal_counts_balls_and_times():
    rng = np.random.default_rng(2)
    scenes = [random_scenario(rng, "three_rods") for _ in range(4)]
    counts = {tuple(len(b.goals) for b in s.bodies) for s in scenes}
    hits = {tuple(b.goals[-2].time for b in s.bodies) for s in scenes}
    balls = {tuple(p.velocity for p in s.props[:3]) for s in scenes}
    assert len(counts) > 1 and len(hits) > 1 and len(balls) == 4
    for s in scenes:
        assert [p.name for p in s.props] == ["ball_gold", "ball_teal", "ball_violet", "target"]
        somersaults = [g for b in s.bodies for g in b.goals if g.relative_rotation is not None]
        assert len(somersaults) == 1 and np.linalg.norm(somersaults[0].relative_rotation) > 6.28


def test_draws_keep_the_planned_demand_inside_the_limits():
    rng = np.random.default_rng(3)
    for family, count in (("intercept", 20), ("three_rods", 2)):
        for _ in range(count):
            scenario = random_scenario(rng, family)
            for body, (force, torque) in zip(scenario.bodies, demand_bounds(scenario), strict=True):
                assert force <= DEMAND_SHARE * body.force_limit
                assert torque <= DEMAND_SHARE * body.torque_limit


def _close(a, b, path: str = "") -> None:
    """Equal structure; floats equal to 1e-9 (the YAML route rounds to 12 digits)."""
    if isinstance(a, tuple | list):
        assert isinstance(b, tuple | list) and len(a) == len(b), path
        for i, (x, y) in enumerate(zip(a, b, strict=True)):
            _close(x, y, f"{path}[{i}]")
    elif hasattr(a, "__dataclass_fields__"):
        assert type(a) is type(b), path
        for name in a.__dataclass_fields__:
            _close(getattr(a, name), getattr(b, name), f"{path}.{name}")
    elif isinstance(a, float) and not isinstance(a, bool):
        assert abs(a - b) <= 1e-9, (path, a, b)
    else:
        assert a == b, (path, a, b)


@pytest.mark.parametrize("k", range(len(ROD_SPECS)))
def test_a_drawn_rod_is_what_the_yaml_route_makes_of_it(k):
    """The draws build model objects straight from the rod's path, skipping the YAML-ready
    entries, the parser and resolve_scenario: same scene up to their rounding, times exact."""
    cfg = RandomThreeRodsConfig()
    rng = np.random.default_rng(40 + k)
    for _ in range(3):
        spec = random_three_rods._rod_spec(rng, ROD_SPECS[k], cfg)
        if k == random_three_rods.SOMERSAULT_ROD:
            spec = random_three_rods._with_somersault(rng, spec)
        candidate = random_three_rods._candidate_of(spec, cfg, fine=2001)
        assert candidate is not None
        fast = random_three_rods._rod_scene(candidate, cfg)
        data = build_three_rods((spec,), name="three_rods_random")
        data["bodies"][0].update(force_limit=cfg.force_limit, torque_limit=cfg.torque_limit)
        slow = resolve_scenario(scenario_from_dict(data), check_plan=False)
        assert fast.resolved
        _close(fast, slow)
        assert [g.time for g in fast.bodies[0].goals] == [g.time for g in slow.bodies[0].goals]


def test_the_rods_routing_is_resolve_goal_times_without_its_checks():
    """The three-rod draws route their goal times with ``_route`` (the routing's arithmetic
    without its per-goal checks): the same floats as ``resolve_goal_times``."""
    rng = np.random.default_rng(4)
    for _ in range(50):
        n = int(rng.integers(3, 30))
        distances = rng.uniform(0.01, 2.0, n).tolist()
        weights = rng.choice([1.0, 0.3], n).tolist()
        critical = sorted({int(j) for j in rng.integers(0, n - 1, 2)} | {n - 2, n - 1})
        times = np.cumsum(rng.uniform(0.1, 1.0, len(critical))).tolist()
        anchors = list(zip(critical, times, strict=True))
        expected = resolve_goal_times(
            [dict(anchors).get(j) for j in range(n)], [j in critical for j in range(n)],
            distances, weights,
        )  # fmt: skip
        assert random_three_rods._route(distances, weights, anchors) == expected.tolist()


def test_the_course_bound_stays_above_the_planners_on_fresh_draws():
    """The planner-free bound the draws check (``course_bound`` with the family's measured
    factors) against the planner's own bound (``demand_bounds``), on rods drawn before any
    feasibility check, from seeds the factors were not measured on."""
    cfg = RandomThreeRodsConfig()
    rng = np.random.default_rng(9)
    checked, worst = 0, 0.0
    for k in range(len(ROD_SPECS)):
        for _ in range(40):
            if checked == 18 * (k + 1):
                break
            candidate = random_three_rods._candidate(rng, k, cfg)
            if candidate is None:
                continue
            scenario = random_three_rods._rod_scene(candidate, cfg)
            bound = random_three_rods.rod_bound(scenario, k)
            # what the draw checks, from the rod's arrays before its scene is built
            assert random_three_rods._candidate_bound(candidate, k) == bound
            if bound is None:
                continue
            ((force, torque),) = demand_bounds(scenario)
            assert force <= bound[0] and torque <= bound[1], (k, force, torque, bound)
            worst = max(worst, force / bound[0], torque / bound[1])
            checked += 1
    assert checked == 54
    print(f"largest planner / course bound over {checked} rods: {worst:.3f}")


def test_a_family_follows_the_env_control_frequency():
    env = SGCEnv(random_scenario="intercept", control_frequency=120)
    env.reset(seed=0)
    assert env.control_frequency == 120
    for goal in env.scenario.bodies[0].goals:
        assert goal.time * 120 == pytest.approx(round(goal.time * 120), abs=1e-9)
    env.close()


def test_the_families_keep_the_tested_margin():
    assert RandomInterceptConfig().demand_share == RandomThreeRodsConfig().demand_share
    assert RandomThreeRodsConfig().demand_share == DEMAND_SHARE


@pytest.mark.parametrize(
    ("config", "field"),
    [
        (lambda: RandomInterceptConfig(meeting_time=(2.0, 1.0)), "meeting_time"),
        (lambda: RandomInterceptConfig(force_limit=1.0), "force_limit"),
        (lambda: RandomThreeRodsConfig(samples_before=(0, 2)), "samples_before"),
        (lambda: RandomThreeRodsConfig(pierce_time=(0.0, 1.0)), "pierce_time"),
    ],
)
def test_bad_ranges_name_the_field(config, field):
    with pytest.raises(ValueError, match=field):
        config()


@pytest.mark.parametrize(
    ("module", "family", "config"),
    [
        (random_intercept, "random_intercept", RandomInterceptConfig(force_limit=5.0)),
        (random_three_rods, "random_three_rods", RandomThreeRodsConfig(force_limit=10.0)),
    ],
)
def test_an_infeasible_family_says_so(monkeypatch, module, family, config):
    monkeypatch.setattr(module, "MAX_DRAWS", 2)
    with pytest.raises(RuntimeError, match="no feasible"):
        getattr(module, family)(np.random.default_rng(0), config)
