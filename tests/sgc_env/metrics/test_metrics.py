"""Metrics on hand-worked cases and on synthetic rollouts."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from baselines.controllers.dynamic_constraints import choose_tau, simulate
from baselines.controllers.minimum_jerk import MinimumJerkPath
from sgc_env.metrics import (
    BodyTrajectory,
    GoalSpec,
    Tolerances,
    angle_travelled,
    closest_approach,
    first_entry,
    integral_of_squares,
    interpolate_at,
    ldlj,
    rotation_ratio,
    score_body,
    score_episode,
    sparc,
    speed_minima,
    step_weights,
    velocity_jump,
)


def min_jerk_speed(duration: float, fs: float) -> np.ndarray:
    s = np.arange(0.0, duration + 0.5 / fs, 1.0 / fs) / duration
    return (30 * s**2 - 60 * s**3 + 30 * s**4) / duration


def reference_sparc(movement, fs, padlevel=4, fc=10.0, amp_th=0.05):
    """The authors' published algorithm, two-sided spectrum and all (for comparison)."""
    nfft = int(2 ** (np.ceil(np.log2(len(movement))) + padlevel))
    f = np.arange(0, fs, fs / nfft)
    mag = np.abs(np.fft.fft(movement, nfft))
    mag = mag / mag.max()
    keep = f <= fc
    f_sel, m_sel = f[keep], mag[keep]
    inx = np.flatnonzero(m_sel >= amp_th)
    f_sel, m_sel = f_sel[inx[0] : inx[-1] + 1], m_sel[inx[0] : inx[-1] + 1]
    return -np.sum(np.sqrt((np.diff(f_sel) / (f_sel[-1] - f_sel[0])) ** 2 + np.diff(m_sel) ** 2))


# --- smoothness -----------------------------------------------------------------------------


def test_ldlj_of_minimum_jerk_stroke():
    dt = 1e-3
    expected = -math.log(720 / 1.875**2)
    assert ldlj(min_jerk_speed(1.0, 1 / dt), dt) == pytest.approx(expected, abs=5e-3)
    assert -math.log(720 / 1.875**2) == pytest.approx(-5.32, abs=5e-3)


def test_ldlj_is_dimensionless_in_duration_and_amplitude():
    base = ldlj(min_jerk_speed(1.0, 1000.0), 1e-3)
    assert ldlj(3.0 * min_jerk_speed(2.0, 1000.0), 1e-3) == pytest.approx(base, abs=5e-3)


def test_ldlj_uses_velocity_vector():
    v = min_jerk_speed(1.0, 1000.0)
    direction = np.array([0.6, 0.0, 0.8])
    assert ldlj(v[:, None] * direction, 1e-3) == pytest.approx(ldlj(v, 1e-3), rel=1e-12)


def test_sparc_reference_gaussian():
    t = np.arange(-1.0, 1.0, 0.01)
    assert t.size == 200
    value = sparc(np.exp(-5 * t**2), 100.0)
    assert value == pytest.approx(-1.414, abs=5e-4)
    assert value == pytest.approx(reference_sparc(np.exp(-5 * t**2), 100.0), abs=1e-12)


def test_sparc_caps_cutoff_at_nyquist_instead_of_mirroring():
    t = np.arange(-1.0, 1.0, 1 / 16)
    v = np.exp(-5 * t**2) * (1 + 0.2 * np.cos(2 * np.pi * 6 * t))
    ours = sparc(v, 16.0, fc=10.0)
    assert ours == pytest.approx(sparc(v, 16.0, fc=8.0), abs=1e-12)
    assert reference_sparc(v, 16.0, fc=10.0) < ours - 0.1


def test_sparc_cutoff_scaled_with_duration_makes_it_duration_free():
    fs = 1000.0
    long, short = min_jerk_speed(1.0, fs), min_jerk_speed(0.1, fs)
    # Equal up to the power-of-two padding, which changes the frequency resolution a little.
    assert sparc(short, fs, fc=10.0 / 0.1) == pytest.approx(sparc(long, fs, fc=10.0), abs=5e-3)
    assert abs(sparc(short, fs, fc=10.0) - sparc(long, fs, fc=10.0)) > 0.05


def test_noise_moves_ldlj_a_lot_and_sparc_little():
    fs = 1000.0
    v = min_jerk_speed(1.0, fs)
    noisy = v + 1e-3 * v.max() * np.random.default_rng(0).normal(size=v.size)
    assert abs(ldlj(noisy, 1 / fs) - ldlj(v, 1 / fs)) > 5.0
    assert abs(sparc(noisy, fs) - sparc(v, fs)) < 0.01


def test_sparc_orders_smooth_before_jerky():
    fs = 100.0
    v = min_jerk_speed(1.0, fs)
    t = np.arange(v.size) / fs
    jerky = v * (1 + 0.3 * np.sin(2 * np.pi * 4 * t))
    assert sparc(jerky, fs) < sparc(v, fs) - 0.2


def test_sparc_and_ldlj_of_a_still_signal_are_nan():
    assert math.isnan(sparc(np.zeros(10), 100.0))
    assert math.isnan(ldlj(np.zeros((10, 3)), 0.01))


def test_speed_minima_counts_prominent_dips_only():
    t = np.linspace(0.0, 2.0, 201)
    two_strokes = np.sin(np.pi * t) ** 2
    assert list(speed_minima(two_strokes, 0.1)) == [100]
    ripple = 1.0 + 0.01 * np.sin(2 * np.pi * 5 * t)
    assert speed_minima(ripple, 0.1).size == 0
    assert speed_minima(ripple, 0.001).size == 10


def test_velocity_jump_across_the_goal_step():
    times = np.arange(1, 6) * 0.1
    v = np.array([[1.0, 0, 0], [1.0, 0, 0], [1.0, 0, 0], [0.0, 1.0, 0], [0.0, 1.0, 0]])
    assert velocity_jump(times, v, 0.3) == pytest.approx(math.sqrt(2.0))
    assert velocity_jump(times, v, 0.2) == pytest.approx(0.0)
    assert math.isnan(velocity_jump(times, v, 0.5))


def test_angle_travelled_and_rotation_ratio():
    dt = 0.01
    times = np.arange(1, 101) * dt
    omega = np.tile([0.0, 0.0, 2.0], (100, 1))
    weights = step_weights(times, dt, 0.0, 0.5)
    assert angle_travelled(omega, weights) == pytest.approx(1.0)
    assert rotation_ratio(1.0, 0.5, 0.05) == pytest.approx(2.0)
    assert rotation_ratio(0.01, 0.0, 0.05) == pytest.approx(0.2)


def test_step_weights_cut_partial_steps():
    times = np.array([0.1, 0.2, 0.3])
    assert np.allclose(step_weights(times, 0.1, 0.05, 0.25), [0.05, 0.1, 0.05])


# --- exactness, punctuality, effort ---------------------------------------------------------


def test_interpolate_at_ticks_and_between():
    times = np.array([0.0, 0.1, 0.3])
    values = np.array([[0.0, 1.0], [1.0, 1.0], [3.0, 0.0]])
    assert np.array_equal(interpolate_at(times, values, 0.1), values[1])
    assert np.allclose(interpolate_at(times, values, 0.2), [2.0, 0.5])
    assert np.array_equal(interpolate_at(times, values, 5.0), values[-1])


def test_closest_approach_refines_between_ticks():
    times = np.arange(0.0, 1.0, 0.1)
    t_pass = 0.4137
    positions = np.stack([times - t_pass, np.full_like(times, 0.05)], axis=1)
    dist = np.linalg.norm(positions, axis=1)
    t_close, d_close = closest_approach(times, dist, 0.2, 0.8)
    assert t_close == pytest.approx(t_pass, abs=1e-12)
    assert d_close == pytest.approx(0.05, abs=1e-12)


def test_closest_approach_exact_hit_and_empty_window():
    times = np.arange(0.0, 1.0, 0.1)
    t_close, d_close = closest_approach(times, np.abs(times - 0.55), 0.0, 1.0)
    assert t_close == pytest.approx(0.55, abs=1e-12)
    assert d_close == pytest.approx(0.0, abs=1e-7)
    assert all(math.isnan(x) for x in closest_approach(times, times, 2.0, 3.0))


def test_first_entry_interpolates_the_crossing():
    times = np.arange(0.0, 1.0, 0.03)
    dist = np.abs(times - 0.5)
    assert first_entry(times, dist, 0.1, 0.0, 1.0) == pytest.approx(0.4, abs=1e-12)
    assert math.isnan(first_entry(times, dist + 1.0, 0.1, 0.0, 1.0))
    assert first_entry(times, dist, 0.1, 0.44, 1.0) == pytest.approx(times[15])


def test_integral_of_squares():
    force = np.tile([0.0, 2.0, 0.0], (100, 1))
    assert integral_of_squares(force, np.full(100, 0.01)) == pytest.approx(4.0)


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda: sparc([], 100.0), "speed"),
        (lambda: sparc([1.0, math.nan], 100.0), "speed"),
        (lambda: sparc([1.0, 2.0], 0.0), "fs"),
        (lambda: ldlj(np.ones(5), -1.0), "dt"),
        (lambda: interpolate_at([0.0, 0.0], [1.0, 2.0], 0.0), "times"),
        (lambda: interpolate_at([0.0, 1.0], [1.0, 2.0, 3.0], 0.0), "values"),
        (lambda: closest_approach([0.0, 1.0], [1.0, 2.0], 1.0, 0.0), "t_end"),
        (lambda: first_entry([0.0, 1.0], [1.0, 2.0], 0.0, 0.0, 1.0), "tolerance"),
        (lambda: GoalSpec(1.0), "nail"),
        (lambda: GoalSpec(math.nan, nail=(0, 0, 0)), "time"),
        (lambda: Tolerances(position=-1.0), "position"),
    ],
)
def test_bad_input_raises_value_error_naming_the_argument(call, match):
    with pytest.raises(ValueError, match=match):
        call()


# --- scorecards from synthetic rollouts -----------------------------------------------------

DT = 1 / 60


def make_infos(positions, velocities, quats=None, omegas=None, forces=None, dt=DT):
    """Infos of one body per step k (time (k+1) dt), in the env's info layout."""
    n = len(positions)
    quats = np.tile([0.0, 0.0, 0.0, 1.0], (n, 1)) if quats is None else quats
    omegas = np.zeros((n, 3)) if omegas is None else omegas
    forces = np.zeros((n, 3)) if forces is None else forces
    return [
        {
            "time": (k + 1) * dt,
            "body_position": positions[k][None],
            "body_velocity": velocities[k][None],
            "body_orientation": quats[k][None],
            "body_angular_velocity": omegas[k][None],
            "point_position": positions[k][None],
            "point_velocity": velocities[k][None],
            "force": forces[k][None],
            "torque": np.zeros((1, 3)),
        }
        for k in range(n)
    ]


NAILS = np.array([[0.0, 0.0, 1.0], [0.5, 0.0, 1.0], [0.5, 0.5, 1.2], [0.0, 0.5, 1.0]])
GOAL_TIMES = np.array([0.0, 1.0, 1.5, 2.5])


def spline_rollout(delay: float = 0.0, n_steps: int = 180):
    path = MinimumJerkPath(GOAL_TIMES, NAILS, np.zeros(3), end_velocity=np.zeros(3))
    t = np.clip((np.arange(n_steps) + 1) * DT - delay, 0.0, GOAL_TIMES[-1])
    return make_infos(path.position(t), path.velocity(t), forces=path.acceleration(t))


def spline_goals():
    return [
        GoalSpec(float(t), nail=tuple(p)) for t, p in zip(GOAL_TIMES[1:], NAILS[1:], strict=True)
    ]


def test_exact_spline_rollout_scores_perfectly():
    traj = BodyTrajectory.from_infos(spline_rollout(), 0, DT)
    card = score_body(traj, spline_goals())
    assert card["success_rate"] == 1.0
    assert card["position_error_max"] < 1e-12
    assert card["position_closest_offset_abs_max"] < 0.01
    assert card["speed_minima_total"] == 0
    assert math.isnan(card["orientation_error_max"])
    assert card["sparc_mean"] < 0 and np.isfinite(card["ldlj_mean"])
    assert card["goal_speed_ratio_min"] > 0.3
    assert card["rotation_excess_total"] == 0.0


def test_late_rollout_fails_and_reports_the_delay():
    card = score_body(BodyTrajectory.from_infos(spline_rollout(0.1), 0, DT), spline_goals())
    assert card["success_rate"] < 1.0
    offsets = [row["closest_offset"] for row in card["position_goals"][:2]]
    assert offsets == pytest.approx([0.1, 0.1], abs=0.01)


def test_goal_between_ticks_is_interpolated():
    goals = [GoalSpec(1.0 + 0.4 * DT, nail=tuple(NAILS[1]))]
    card = score_body(BodyTrajectory.from_infos(spline_rollout(0.4 * DT), 0, DT), goals)
    # Linear interpolation of a curved path: error of order |a| dt^2 / 8.
    assert card["position_error_max"] < 1e-3
    assert card["success_rate"] == 1.0


def test_met_is_the_state_at_the_goals_own_time() -> None:
    """One tick late is a miss by default; a time tolerance is an explicit option that counts
    the tick within it."""
    late = BodyTrajectory.from_infos(spline_rollout(DT), 0, DT)  # one tick behind the spline
    goals = spline_goals()[:2]  # both reached at speed: a tick late is about a centimetre off
    strict = Tolerances(position=0.005)
    by_default = score_body(late, goals, tolerances=strict)
    assert by_default["goals_met"] == 0
    assert all(row["position_error"] > 0.005 for row in by_default["position_goals"])
    loose = score_body(late, goals, tolerances=Tolerances(position=0.005, time=DT))
    assert loose["goals_met"] == len(goals)
    assert Tolerances().time == 0.0


def test_dynamic_constraints_rollout_shows_the_figure_1_pathology():
    eps = 1e-3
    taus = [
        choose_tau(float(t1 - t0), float(np.linalg.norm(b - a)), eps)
        for t0, t1, a, b in zip(GOAL_TIMES[:-1], GOAL_TIMES[1:], NAILS[:-1], NAILS[1:], strict=True)
    ]
    sim = simulate(NAILS[0], np.zeros(3), NAILS[1:], taus, eps, DT, 3.0)
    infos = make_infos(sim.positions[1:], sim.velocities[1:])
    card = score_body(BodyTrajectory.from_infos(infos, 0, DT), spline_goals())
    smooth = score_body(BodyTrajectory.from_infos(spline_rollout(), 0, DT), spline_goals())
    assert card["goal_speed_ratio_min"] < 0.1 < smooth["goal_speed_ratio_min"]
    assert card["position_entry_offset_abs_max"] > 0.05
    assert card["speed_minima_total"] >= 2 and smooth["speed_minima_total"] == 0
    assert card["sparc_track"] < smooth["sparc_track"] - 1.0
    assert card["ldlj_mean"] < smooth["ldlj_mean"]


def test_rotation_metrics_for_a_spin_and_a_wobble():
    n, rate = 120, math.pi / 2
    t = (np.arange(n) + 1) * DT
    quats = Rotation.from_rotvec(np.outer(rate * t, [0, 0, 1])).as_quat()
    omegas = np.tile([0.0, 0.0, rate], (n, 1))
    still = np.zeros((n, 3))
    infos = make_infos(still, still, quats, omegas)
    initial = {key: value for key, value in infos[0].items() if key != "time"}
    initial["body_orientation"] = np.array([[0.0, 0.0, 0.0, 1.0]])
    goals = [
        GoalSpec(1.0, orientation=tuple(Rotation.from_rotvec([0, 0, rate]).as_quat())),
        GoalSpec(2.0, orientation=tuple(Rotation.from_rotvec([0, 0, 2 * rate]).as_quat())),
    ]
    card = score_body(BodyTrajectory.from_infos(infos, 0, DT, initial), goals)
    assert card["orientation_error_max"] < 1e-12
    assert card["rotation_ratio_max"] == pytest.approx(1.0, abs=1e-9)
    assert card["success_rate"] == 1.0
    assert math.isnan(card["position_error_max"])
    wobble = np.outer(0.3 * np.sin(2 * np.pi * t), [1, 0, 0])
    infos = make_infos(
        still, still, Rotation.from_rotvec(wobble).as_quat(), np.gradient(wobble, DT, axis=0)
    )
    card = score_body(
        BodyTrajectory.from_infos(infos, 0, DT), [GoalSpec(1.0, orientation=(0, 0, 0, 1))]
    )
    assert card["rotation_ratio_max"] > 10.0


def test_somersault_uses_the_given_rotation_angle():
    n, rate = 60, 2 * math.pi
    t = (np.arange(n) + 1) * DT
    quats = Rotation.from_rotvec(np.outer(rate * t, [1, 0, 0])).as_quat()
    omegas = np.tile([rate, 0.0, 0.0], (n, 1))
    infos = make_infos(np.zeros((n, 3)), np.zeros((n, 3)), quats, omegas)
    goal = GoalSpec(1.0, orientation=(0, 0, 0, 1), rotation_angle=2 * math.pi)
    card = score_body(BodyTrajectory.from_infos(infos, 0, DT), [goal])
    assert card["orientation_error_max"] < 1e-9
    assert card["success_rate"] == 1.0
    assert card["rotation_ratio_max"] == pytest.approx(1.0, abs=1e-9)


def test_effort_integrates_held_forces():
    n = 60
    forces = np.tile([3.0, 0.0, 4.0], (n, 1))
    infos = make_infos(np.zeros((n, 3)), np.zeros((n, 3)), forces=forces)
    card = score_body(BodyTrajectory.from_infos(infos, 0, DT), [GoalSpec(0.5, nail=(0, 0, 0))])
    assert card["force_sq_integral"] == pytest.approx(25.0)
    assert card["force_peak"] == pytest.approx(5.0)
    assert card["torque_sq_integral"] == 0.0


def test_score_episode_aggregates_bodies():
    one = spline_rollout()
    late = spline_rollout(0.1)
    infos = []
    for a, b in zip(one, late, strict=True):
        merged = {"time": a["time"]}
        for key in a:
            if key != "time":
                merged[key] = np.concatenate([a[key], b[key]])
        infos.append(merged)
    result = score_episode(infos, [spline_goals(), spline_goals()], DT)
    bodies = result["bodies"]
    assert result["n_goals"] == 6
    assert result["goals_met"] == bodies[0]["goals_met"] + bodies[1]["goals_met"]
    assert result["success_rate"] == pytest.approx(result["goals_met"] / 6)
    assert result["position_error_max"] == max(b["position_error_max"] for b in bodies)
    skipped = score_episode(infos, [spline_goals(), []], DT)
    assert skipped["bodies"][1] is None and skipped["n_goals"] == 3


def test_score_body_rejects_bad_goals():
    traj = BodyTrajectory.from_infos(spline_rollout(), 0, DT)
    with pytest.raises(ValueError, match="goals"):
        score_body(traj, [])
    with pytest.raises(ValueError, match="increasing"):
        score_body(traj, [GoalSpec(1.0, nail=(0, 0, 0)), GoalSpec(1.0, nail=(1, 0, 0))])
    with pytest.raises(ValueError, match="infos"):
        BodyTrajectory.from_infos([], 0, DT)
    with pytest.raises(ValueError, match="body_index"):
        BodyTrajectory.from_infos(spline_rollout(), 3, DT)


def test_still_body_gives_nan_smoothness_not_noise():
    n = 60
    noise = 1e-12 * np.random.default_rng(0).normal(size=(n, 3))
    infos = make_infos(np.zeros((n, 3)), noise, omegas=noise)
    card = score_body(BodyTrajectory.from_infos(infos, 0, DT), [GoalSpec(0.5, nail=(0, 0, 0))])
    assert math.isnan(card["sparc_mean"]) and math.isnan(card["ldlj_mean"])
    assert math.isnan(card["angular_sparc_mean"]) and math.isnan(card["sparc_track"])
    assert card["speed_minima_total"] == 0


# --- scenarios and the real env -------------------------------------------------------------


def test_goals_from_scenario_resolves_relative_rotations():
    from sgc_env.metrics import goals_from_scenario
    from sgc_env.scenario import load_scenario

    scenario = load_scenario("rod_basic")
    (goals,) = goals_from_scenario(scenario)
    body = scenario.bodies[0]
    assert [g.time for g in goals] == [float(g.time) for g in body.goals]
    assert goals[0].point == (0.0, 0.0, 0.3)
    assert goals[1].orientation is None
    rel = np.asarray(body.goals[2].relative_rotation)
    want = Rotation.from_rotvec(rel) * Rotation.from_quat(body.goals[0].orientation)
    got = Rotation.from_quat(goals[2].orientation)
    assert (got * want.inv()).magnitude() < 1e-9
    assert goals[2].rotation_angle == pytest.approx(np.linalg.norm(rel))


def test_scores_a_real_env_rollout_that_tracks_the_spline():
    from sgc_env.envs.sgc_env import SGCEnv
    from sgc_env.metrics import goals_from_scenario

    env = SGCEnv(scenario="point_three_goals")
    try:
        _, initial = env.reset(seed=0)
        scenario, dt = env.scenario, env.dt
        body = scenario.bodies[0]
        (goals,) = goals_from_scenario(scenario)
        path = MinimumJerkPath(
            [0.0, *[g.time for g in goals]],
            [body.position, *[g.nail for g in goals]],
            body.linear_velocity,
        )
        gravity = np.asarray(scenario.gravity)
        infos, info, done, k = [], initial, False, 0
        while not done:
            t = k * dt
            x, v = info["body_position"][0], info["body_velocity"][0]
            a = path.acceleration(t + dt / 2)
            a = a + 400 * (path.position(t) - x) + 40 * (path.velocity(t) - v)
            action = np.clip(body.mass * (a - gravity) / body.force_limit, -1, 1)
            _, _, terminated, truncated, info = env.step(action)
            infos.append(info)
            done, k = terminated or truncated, k + 1
    finally:
        env.close()
    result = score_episode(infos, [goals], dt, initial_info=initial)
    assert result["success_rate"] == 1.0
    assert result["position_error_max"] < 2e-3
    assert result["position_closest_offset_abs_max"] < dt
    assert result["force_peak"] > body.mass * 9.0


def test_goals_after_the_rollout_ended_fail_with_nan_errors():
    infos = spline_rollout(n_steps=80)  # ends at 1.33 s, before the goals at 1.5 and 2.5 s
    card = score_body(BodyTrajectory.from_infos(infos, 0, DT), spline_goals())
    assert card["met"] == [True, False, False]
    assert card["goals_after_end"] == 2
    assert [math.isnan(r["position_error"]) for r in card["position_goals"]] == [False, True, True]


def test_closest_approach_on_segments_is_exact_at_a_hit_with_a_speed_change():
    # Through the nail on the tick at t = 0.5, fast before and slow after: a parabola through
    # the squared distances would put the vertex ~0.3 ticks late; the segments do not.
    times = np.arange(11) / 10.0
    offsets = np.where((times < 0.5)[:, None], [[4.0, 0.0, 0.0]], [[1.0, 0.0, 0.0]]) * (
        times[:, None] - 0.5
    )
    t_close, d_close = closest_approach(times, offsets, 0.0, 1.0)
    assert t_close == 0.5 and d_close == 0.0
    t_scalar, _ = closest_approach(times, np.linalg.norm(offsets, axis=1), 0.0, 1.0)
    assert t_scalar != 0.5


def test_orientation_closest_approach_is_exact_at_a_hit_with_a_speed_change():
    # A spin that passes the goal orientation on the tick at t = 1.0, fast before and slow
    # after: the squared-angle parabola would put the closest approach late.
    t = (np.arange(120) + 1) * DT
    angle = np.where(t < 1.0, 4.0, 1.0) * (t - 1.0)
    quats = Rotation.from_rotvec(np.outer(angle, [0, 1, 0])).as_quat()
    still = np.zeros((t.size, 3))
    infos = make_infos(still, still, quats, np.outer(np.gradient(angle, DT), [0, 1, 0]))
    card = score_body(
        BodyTrajectory.from_infos(infos, 0, DT), [GoalSpec(1.0, orientation=(0, 0, 0, 1))]
    )
    goal = card["orientation_goals"][0]
    assert abs(goal["closest_offset"]) < 1e-12 and goal["closest_angle"] < 1e-12
    parabola_time, _ = closest_approach(t, np.abs(angle), 0.5, 1.5)
    assert abs(parabola_time - 1.0) > 0.1 * DT


def test_closest_approach_on_segments_between_ticks():
    times = np.arange(11) / 10.0
    offsets = np.stack([times - 0.537, np.full_like(times, 0.01), np.zeros_like(times)], axis=1)
    t_close, d_close = closest_approach(times, offsets, 0.2, 0.8)
    assert t_close == pytest.approx(0.537, abs=1e-12)
    assert d_close == pytest.approx(0.01, abs=1e-12)
