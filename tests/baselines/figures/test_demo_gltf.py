"""The demo's glTF file, read back by the tests' own reader: every one of the 58 goals where the
env put the rod, the three rods keyframed at the control rate, the balls where the video draws
them, and nothing written with ``--no-gltf``."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from baselines.cli.main import main
from baselines.figures.demo import GLTF_FILE, BallCarry, DemoOptions, pierce_times, run_demo
from sgc_env.scenes import three_rods
from tests.sgc_env.export.glb_reader import read_glb

TOLERANCE = 1e-6
"""m and rad: the file against the env at every goal's tick (float32 keyframes)."""


@pytest.fixture(scope="module")
def demo(tmp_path_factory):
    out = tmp_path_factory.mktemp("demo")
    from baselines.controllers.expert import SGCExpert
    from baselines.evaluation.harness import run_episode

    result = run_demo(DemoOptions(out=out, video=False))
    import gymnasium as gym

    env = gym.make("SGCThreeRods-v2")
    record = run_episode(SGCExpert(env), env, seed=0, keep_infos=True)  # the env's own numbers
    scenario = env.unwrapped.scenario
    env.close()
    return result, read_glb(out / GLTF_FILE), [record.initial_info, *record.infos], scenario


def test_every_goal_of_the_demo_is_where_the_env_put_the_tip(demo):
    result, glb, infos, scenario = demo
    assert result.summary["goals_met"] == 58
    checked = 0
    for b, body in enumerate(scenario.bodies):
        node = glb.node_index(f"expert/{body.name}")
        up = glb.world_of_parent(node)
        times, translations = glb.keyframes("expert", node, "translation")
        _, rotations = glb.keyframes("expert", node, "rotation")
        np.testing.assert_allclose(np.diff(times), 1 / 60, rtol=0, atol=1e-5)  # control rate
        for goal in body.goals:
            tick = round(goal.time * 60)
            info = infos[tick]
            env_rotation = Rotation.from_quat(info["body_orientation"][b])
            file_rotation = up * Rotation.from_quat(rotations[tick].astype(float))
            tip = up.apply(info["point_position"][b])
            file_tip = up.apply(translations[tick].astype(float)) + file_rotation.apply(
                three_rods.TIP)
            assert np.linalg.norm(file_tip - tip) <= TOLERANCE, (body.name, goal.time)
            assert (file_rotation * (up * env_rotation).inv()).magnitude() <= TOLERANCE
            if goal.nail is not None:  # and the tip is on the nail, as the expert meets it
                assert np.linalg.norm(file_tip - up.apply(goal.nail)) <= TOLERANCE
            checked += 1
    assert checked == 58


def test_the_balls_ride_where_the_video_draws_them(demo):
    _, glb, infos, scenario = demo
    times = [info["time"] for info in infos]
    tips = np.stack([np.asarray(info["point_position"]) for info in infos])
    carry = BallCarry(scenario, pierce_times(scenario, times, tips))
    last = infos[-1]
    drawn = carry.positions(times[-1], last["body_position"], last["body_orientation"])
    for k in carry.ball_index:
        name = scenario.props[k].name
        _, path = glb.keyframes("expert", glb.node_index(f"expert/{name}"), "translation")
        np.testing.assert_allclose(path[-1], drawn[k], rtol=0, atol=1e-5)
        centre = np.asarray(last["body_position"][carry.ball_index.index(k)])
        assert np.linalg.norm(path[-1] - centre) < 1e-5  # slid to the middle of its rod
    board = glb.doc["nodes"][glb.node_index("target")]
    assert len(board["children"]) == 4  # the bullseye rings


def test_no_gltf_writes_none(tmp_path):
    out = tmp_path / "demo"
    assert main(["demo", "--out", str(out), "--no-video", "--no-gltf"]) == 0
    assert not (out / GLTF_FILE).exists() and (out / "summary.json").exists()
