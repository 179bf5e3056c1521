"""The paper's three-rod demo: scene, exactness, piercing, hitting, integrity, outputs."""

from __future__ import annotations

import json

import gymnasium as gym
import numpy as np
import pytest
import yaml

import sgc_env
from baselines.cli.main import main
from baselines.controllers.expert import SGCExpert
from baselines.evaluation.harness import run_episode
from baselines.figures.demo import DemoOptions, DemoScene, gif_durations, pierce_times
from baselines.figures.demo_camera import DEMO_SHOTS, camera_at
from sgc_env.paper.frames import normalized_frame
from sgc_env.scenario.load import builtin_path
from sgc_env.scenes import three_rods
from sgc_env.simulator import pybullet
from tests.sgc_env.export.glb_reader import read_glb

OUTPUTS = {
    "three_rods.mp4", "three_rods.gif", "plates.png", "deviation.png", "speed.png", "goals.csv",
    "summary.json", "rods.json", "three_rods.glb", "viewer.html",
}  # fmt: skip
"""What one run of ``sgc demo`` writes, whichever policy flies it."""
MIN_SPEED_FRACTION = 0.1
"""A rod 'never stops': its tip speed stays above this fraction of its mean flight speed."""


@pytest.fixture(scope="module")
def episode():
    env = gym.make("SGCThreeRods-v2")
    record = run_episode(SGCExpert(env), env, seed=0, keep_infos=True)
    scenario = env.unwrapped.scenario
    env.close()
    return record, scenario


def _tips(record) -> tuple[np.ndarray, np.ndarray]:
    infos = [record.initial_info, *record.infos]
    times = np.array([info.get("time", 0.0) for info in infos])
    return times, np.stack([np.asarray(info["point_position"]) for info in infos])


YAML_DIGIT_TOLERANCE = 1e-11
"""The builder rounds every number to 12 decimals; a scipy or numpy release can move a value
across a rounding boundary (4.8038548213515 seen), so a rebuilt value may differ from the
shipped one by one unit in the 12th decimal, and never by more."""


def _assert_same_tree(shipped, built, path: str = "") -> None:
    """Structure, keys and strings equal; numbers equal to the builder's rounding."""
    if isinstance(shipped, dict):
        assert isinstance(built, dict) and shipped.keys() == built.keys(), path
        for key in shipped:
            _assert_same_tree(shipped[key], built[key], f"{path}.{key}")
    elif isinstance(shipped, list):
        assert isinstance(built, list) and len(shipped) == len(built), path
        for index, (a, b) in enumerate(zip(shipped, built, strict=True)):
            _assert_same_tree(a, b, f"{path}[{index}]")
    elif isinstance(shipped, float) or isinstance(built, float):
        assert abs(float(shipped) - float(built)) <= YAML_DIGIT_TOLERANCE, (path, shipped, built)
    else:
        assert shipped == built, path


def test_shipped_yaml_is_what_the_builder_makes():
    shipped = yaml.safe_load(builtin_path("three_rods").read_text())
    _assert_same_tree(shipped, yaml.safe_load(yaml.safe_dump(three_rods.build_three_rods())))
    assert [len(b["goals"]) for b in shipped["bodies"]] == [25, 16, 17]
    somersaults = [g for b in shipped["bodies"] for g in b["goals"] if "relative_rotation" in g]
    assert len(somersaults) == 1
    assert np.linalg.norm(somersaults[0]["relative_rotation"]) > 2 * np.pi


def test_yaml_comparison_catches_a_value_moved_past_rounding():
    built = yaml.safe_load(yaml.safe_dump(three_rods.build_three_rods()))
    moved = yaml.safe_load(yaml.safe_dump(built))
    moved["bodies"][0]["goals"][3]["point"][0] += 1e-9
    with pytest.raises(AssertionError):
        _assert_same_tree(built, moved)


def test_every_rod_meets_every_goal_exactly(episode):
    record, scenario = episode
    assert not record.terminated
    events = [e for info in record.infos for e in info.get("goal_reached", [])]
    assert len(events) == sum(len(b.goals) for b in scenario.bodies) == 58
    for event in events:
        assert event["position_error"] <= 1e-9
        assert event["orientation_error"] is None or event["orientation_error"] <= 1e-9
    for info in record.infos:
        for force, body in zip(info["force"], scenario.bodies, strict=True):
            assert np.linalg.norm(force, np.inf) <= body.force_limit


def test_tips_pierce_their_balls_and_hit_the_target(episode):
    record, scenario = episode
    times, tips = _tips(record)
    props = {p.name: p for p in scenario.props}
    target = props["target"]
    face_x = target.position[0] - target.size[0]
    for b, body in enumerate(scenario.bodies):
        ball = props[f"ball_{body.name[4:]}"]
        tick = int(np.argmin(np.abs(times - three_rods.PIERCE_TIME)))
        assert np.linalg.norm(tips[tick, b] - ball.position_at(times[tick])) < 1e-9
        hit = [g for g in body.goals if g.time is not None][-2]
        tick = int(np.argmin(np.abs(times - hit.time)))
        assert abs(tips[tick, b, 0] - face_x) < 1e-9
        assert abs(tips[tick, b, 1] - target.position[1]) < target.size[1]
        assert abs(tips[tick, b, 2] - target.position[2]) < target.size[2]


def test_rods_never_stop_and_never_oscillate_along_a_course(episode):
    record, scenario = episode
    times, tips = _tips(record)
    speeds = np.linalg.norm(np.diff(tips, axis=0), axis=2) / np.diff(times)[:, None]
    for b, body in enumerate(scenario.bodies):
        nails = [np.asarray(g.nail) for g in body.goals]
        goal_times = [g.time for g in body.goals]
        flight = times[1:] <= goal_times[-2]
        assert speeds[flight, b].min() >= MIN_SPEED_FRACTION * speeds[flight, b].mean()
        previous, start = tips[0, b], 0.0
        for j, (nail, end) in enumerate(zip(nails[:-1], goal_times[:-1], strict=True)):
            frame = normalized_frame(previous - nail, nail - nails[j + 1])
            inside = (times >= start) & (times < end - 1e-9)
            components = (tips[inside, b] - nail) @ frame.T
            # every component of the deviation in S_i keeps its sign: no overshoot, no swing
            assert np.all(components > 0.0), (body.name, j)
            previous, start = nail, end


def test_demo_command_writes_every_output(tmp_path, capsys):
    out = tmp_path / "demo"
    code = main(["demo", "--out", str(out), "--width", "96", "--height", "64"])
    assert code == 0
    assert OUTPUTS <= {p.name for p in out.iterdir()}
    rods = json.loads((out / "rods.json").read_text())
    assert [r["goals"] for r in rods] == [25, 16, 17]
    assert all(r["position_error_max_m"] <= 1e-9 for r in rods)
    printed = capsys.readouterr().out
    assert "58/58 goals met" in printed and "CPU" in printed and "tangent rule" in printed


def test_demo_can_show_the_papers_rule(tmp_path, capsys):
    out = tmp_path / "paper"
    assert main(["demo", "--out", str(out), "--no-video", "--paper-rule"]) == 0
    printed = capsys.readouterr().out
    assert "paper's k rules" in printed and "58/58 goals met" in printed
    assert json.loads((out / "summary.json").read_text())["position_error_max"] <= 1e-9


def test_demo_flies_another_policy_with_the_same_outputs(tmp_path, capsys):
    out = tmp_path / "random"
    code = main(["demo", "--policy", "random", "--out", str(out), "--width", "64",
                 "--height", "48"])  # fmt: skip
    assert code == 0  # a policy that misses goals is reported, not an error
    assert OUTPUTS <= {p.name for p in out.iterdir()}
    summary = json.loads((out / "summary.json").read_text())
    assert summary["goals_met"] < 58
    assert {row.split(",")[1] for row in (out / "goals.csv").read_text().splitlines()[1:]} == {
        "random"
    }
    printed = capsys.readouterr().out
    assert "policy random, scored by the harness" in printed
    assert f"random: {summary['goals_met']}/58 goals met" in printed


@pytest.mark.parametrize(
    ("argv", "labels"),
    [
        (["--compare", "expert,random"], ["expert", "random"]),
        (["--compare", "expert,random", "--paper-rule"], ["expert-paper", "random"]),
        (["--paper-rule"], ["expert-paper"]),
    ],
)
def test_demo_labels_say_which_rule_flew_the_expert(argv, labels):
    import argparse

    from baselines.cli.commands import demo as demo_command

    parser = argparse.ArgumentParser()
    demo_command.add_arguments(parser)
    args = parser.parse_args(argv)
    assert demo_command._labels(args, demo_command._specs(args)) == labels


def test_demo_compare_paper_rule_against_expert_paper_is_refused(capsys):
    assert main(["demo", "--compare", "expert,expert-paper", "--paper-rule"]) == 2
    assert "more than once" in capsys.readouterr().err


def test_demo_compare_writes_both_runs_side_by_side(tmp_path, capsys):
    import imageio.v2 as imageio

    out = tmp_path / "compare"
    code = main(["demo", "--compare", "expert,random", "--out", str(out), "--width", "64",
                 "--height", "48"])  # fmt: skip
    assert code == 0
    summaries = json.loads((out / "summary.json").read_text())
    assert set(summaries) == {"expert", "random"}
    assert summaries["expert"]["goals_met"] == 58 > summaries["random"]["goals_met"]
    expert = imageio.mimread(out / "expert" / "three_rods.mp4", memtest=False)
    rand = imageio.mimread(out / "random" / "three_rods.mp4", memtest=False)
    both = imageio.mimread(out / "compare.mp4", memtest=False)
    assert (out / "random" / "plates.png").exists()
    assert both[0].shape == (48, 128, 3) and expert[0].shape == (48, 64, 3)
    assert len(both) == len(expert) > len(rand)  # random ended early: its last frame is held
    scene = read_glb(out / "compare.glb")  # both flights in one scene, an animation each
    assert [a["name"] for a in scene.doc["animations"]] == ["expert", "random"]
    assert (out / "viewer.html").exists() and (out / "random" / "three_rods.glb").exists()

    def gap(a, b):  # below the caption band, H.264 noise of a few levels
        return np.abs(a[30:].astype(int) - b[30:].astype(int)).mean()

    for i in (len(both) // 2, len(both) - 1):
        left, right = both[i][:, :64], both[i][:, 64:]
        assert gap(left, expert[i]) < 8.0 < gap(left, rand[-1])
        assert gap(right, rand[-1]) < 8.0 < gap(right, expert[i])
    printed = capsys.readouterr().out
    assert "the expert (the tangent rule)" in printed and "policy random" in printed


@pytest.mark.parametrize(
    ("argv", "problem"),
    [
        (["--policy", "nonsense"], "unknown spec 'nonsense'"),
        (["--policy", "shipped:SGCPoint-v1"], "(trained on SGCPoint-v1)"),
        (["--policy", "random", "--paper-rule"], "--paper-rule: applies to the expert"),
        (["--compare", "expert"], "expected two specs"),
        (["--compare", "expert,random", "--no-video"], "drop --no-video"),
    ],
)
def test_demo_bad_policy_exits_2_with_one_line(argv, problem, tmp_path, capsys):
    out = tmp_path / "demo"
    extra = [] if "--no-video" in argv else ["--no-video"]
    assert main(["demo", *argv, "--out", str(out), *extra]) == 2
    err = capsys.readouterr().err
    assert err.startswith("sgc demo: error:") and err.count("\n") == 1, err
    assert problem in err
    assert not out.exists() or not any(out.iterdir())


def test_gif_delays_add_up_to_real_time():
    """GIF delays are whole centiseconds: 15 fps needs 70, 70, 60 ms, never all 60 or 70."""
    durations = gif_durations(130, 15.0)
    assert all(d % 10 == 0 for d in durations)
    elapsed = np.cumsum(durations)
    real = np.arange(1, 131) * 1000.0 / 15.0
    assert np.max(np.abs(elapsed - real)) <= 5.0
    assert set(durations) == {60, 70}


def test_expert_pierces_every_ball_on_the_pierce_tick(episode):
    record, scenario = episode
    times, tips = _tips(record)
    assert pierce_times(scenario, times, tips) == [three_rods.PIERCE_TIME] * 3


def test_a_ball_the_tip_never_meets_is_not_pierced(episode):
    record, scenario = episode
    times, tips = _tips(record)
    moved = tips.copy()
    moved[:, 1] += np.array([0.0, 0.0, 0.5])  # teal's tip passes 0.5 m above its 0.22 m ball
    pierced = pierce_times(scenario, times, moved)
    assert pierced[1] is None and pierced[0] == pierced[2] == three_rods.PIERCE_TIME
    late = tips.copy()
    late[times < 2.0, 2] = 100.0  # violet only ever meets its ball after 2 s: none left by then
    assert pierce_times(scenario, times, late)[2] is None


def test_pierced_balls_ride_their_rods_and_missed_ones_fly_on():
    env = gym.make("SGCThreeRods-v2")
    _, info = env.reset(seed=0)
    base = env.unwrapped
    with pytest.raises(ValueError, match="one time per rod"):
        DemoScene(base.scenario, [1.0])
    scene = DemoScene(base.scenario, [three_rods.PIERCE_TIME, three_rods.PIERCE_TIME, None])
    client = scene.client
    positions, orientations = info["body_position"], info["body_orientation"]
    before = three_rods.PIERCE_TIME - 0.5
    scene.update(before, positions, orientations)
    balls = [base.scenario.props[k] for k in scene.carry.ball_index]
    for ball, uid in zip(balls, scene.ball_uids, strict=True):
        at = pybullet.getBasePositionAndOrientation(uid, physicsClientId=client)[0]
        np.testing.assert_allclose(at, ball.position_at(before), atol=1e-12)
    later = three_rods.PIERCE_TIME + 1.0
    scene.update(later, positions, orientations)  # slid to the middle
    for rod, uid in zip(scene.rods[:2], scene.ball_uids[:2], strict=True):
        centre = pybullet.getBasePositionAndOrientation(rod, physicsClientId=client)[0]
        at = pybullet.getBasePositionAndOrientation(uid, physicsClientId=client)[0]
        np.testing.assert_allclose(at, centre, atol=1e-12)
    at = pybullet.getBasePositionAndOrientation(scene.ball_uids[2], physicsClientId=client)[0]
    np.testing.assert_allclose(at, balls[2].position_at(later), atol=1e-12)  # never met
    scene.close()
    env.close()


def test_cameras_look_where_the_shots_say():
    for shot in DEMO_SHOTS:
        view = camera_at(shot.time, 320, 180)
        px, depth = view.project(np.array([shot.look_at]))
        np.testing.assert_allclose(px[0], [160.0, 90.0], atol=1e-3)
        assert depth[0] == pytest.approx(shot.distance, rel=1e-6)  # float32 matrices


def test_demo_options_are_validated():
    with pytest.raises(ValueError, match="width"):
        DemoOptions(out=sgc_env.__path__[0], width=0)


def test_target_board_whole_in_frame_once_the_flight_is_on():
    """From 2.6 s (the wide shot) to the end, all 8 corners of the board project inside."""
    from sgc_env.render import box_corners

    scenario = sgc_env.load_scenario("three_rods")
    board = next(p for p in scenario.props if p.name == "target")
    corners = box_corners(board.position, board.size)
    end = max(float(g.time) for b in scenario.bodies for g in b.goals) + scenario.margin
    for t in np.arange(2.6, end, 1.0 / 30.0):
        view = camera_at(float(t), 960, 540)
        px, depth = view.project(corners)
        assert np.all(depth > 0.0)
        assert np.all((px >= 0.0) & (px <= [960.0, 540.0])), t
