"""The glTF writer: every id's flight read back (by the tests' own reader) as the env put it, the
meshes closed and outward, colours and names as rendered, bad input refused before any work."""

from __future__ import annotations

import dataclasses

import gymnasium as gym
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import sgc_env
from sgc_env.export import gltf
from sgc_env.export.gltf import Motion, glb_bytes, linear_color, motion_of, write_glb
from sgc_env.export.meshes import box_mesh, cylinder_mesh, sphere_mesh
from sgc_env.metrics.scenario_goals import goals_from_scenario
from tests.sgc_env.export.glb_reader import read_glb

POSITION_TOLERANCE = 1e-6
"""m: the file's body point at a goal's tick against the env's (float32 keyframes)."""
ORIENTATION_TOLERANCE = 1e-6
"""rad: the file's orientation at a goal's tick against the env's."""


def _flight(env_id: str, seed: int = 3) -> tuple[gym.Env, list[dict]]:
    """An episode of seeded random actions: the reset's info, then every step's."""
    env = gym.make(env_id)
    _, info = env.reset(seed=seed)
    env.action_space.seed(seed)
    infos = [info]
    done = False
    while not done:
        _, _, terminated, truncated, info = env.step(env.action_space.sample())
        infos.append(info)
        done = terminated or truncated
    return env, infos


def _registered() -> list[str]:
    return sorted(k for k in gym.registry if k.startswith("SGC"))


@pytest.mark.parametrize("env_id", _registered())
def test_every_goal_tick_of_every_id_reads_back_as_the_env_put_it(env_id, tmp_path):
    env, infos = _flight(env_id)
    base = env.unwrapped
    path = write_glb(tmp_path / "flight.glb", base.scenario, [motion_of("random", infos)])
    glb = read_glb(path)
    assert [a["name"] for a in glb.doc["animations"]] == ["random"]
    goals = goals_from_scenario(base.scenario)
    checked = 0
    for b, body in enumerate(base.scenario.bodies):
        node = glb.node_index(f"random/{body.name}")
        up = glb.world_of_parent(node)
        times, translations = glb.keyframes("random", node, "translation")
        _, rotations = glb.keyframes("random", node, "rotation")
        assert len(times) == len(infos)
        for goal, spec in zip(body.goals, goals[b], strict=True):
            tick = round(spec.time * base.control_frequency)
            if tick >= len(infos):  # the episode ended (terminated) before this goal's time
                continue
            info = infos[tick]
            assert times[tick] == np.float32(spec.time)
            env_rotation = Rotation.from_quat(info["body_orientation"][b])
            file_rotation = up * Rotation.from_quat(rotations[tick].astype(float))
            point = np.asarray(goal.point, float)
            env_point = up.apply(info["body_position"][b] + env_rotation.apply(point))
            file_point = up.apply(translations[tick].astype(float)) + file_rotation.apply(point)
            assert np.linalg.norm(file_point - env_point) <= POSITION_TOLERANCE
            angle = (file_rotation * (up * env_rotation).inv()).magnitude()
            assert angle <= ORIENTATION_TOLERANCE
            checked += 1
    assert checked > 0
    nails = [n for n in glb.doc["nodes"] if n.get("name", "").startswith("nail.")]
    assert len(nails) == sum(s.nail is not None for specs in goals for s in specs)
    for node in nails:
        spec = goals[[b.name for b in base.scenario.bodies].index(node["extras"]["body"])]
        nail = spec[node["extras"]["goal"]]
        assert node["extras"]["time"] == nail.time
        np.testing.assert_allclose(node["translation"], nail.nail, rtol=0, atol=1e-15)


def test_the_root_turns_z_up_into_y_up(tmp_path):
    env, infos = _flight("SGCPoint-v1")
    glb = read_glb(write_glb(tmp_path / "f.glb", env.unwrapped.scenario, [motion_of("a", infos)]))
    up = glb.world_of_parent(glb.node_index("a/" + env.unwrapped.scenario.bodies[0].name))
    np.testing.assert_allclose(up.apply([0.0, 0.0, 1.0]), [0.0, 1.0, 0.0], atol=1e-15)
    np.testing.assert_allclose(up.apply([0.0, 1.0, 0.0]), [0.0, 0.0, -1.0], atol=1e-15)


def test_two_motions_are_two_named_animations_of_their_own_groups(tmp_path):
    env, infos = _flight("SGCThreeRods-v2")
    scenario = env.unwrapped.scenario
    first = motion_of("expert", infos)
    second = dataclasses.replace(first, label="learner", positions=first.positions + 1.0)
    glb = read_glb(write_glb(tmp_path / "two.glb", scenario, [first, second]))
    assert [a["name"] for a in glb.doc["animations"]] == ["expert", "learner"]
    names = [n.get("name") for n in glb.doc["nodes"]]
    for anim in glb.doc["animations"]:
        targets = {names[c["target"]["node"]] for c in anim["channels"]}
        assert targets and all(t.startswith(anim["name"] + "/") for t in targets)
        group = [n for n in glb.doc["nodes"] if n.get("name") == anim["name"]][0]
        assert {names[c] for c in group["children"]} == targets
    node = glb.node_index("learner/rod_gold")
    _, moved = glb.keyframes("learner", node, "translation")
    np.testing.assert_allclose(moved, first.positions[:, 0] + 1.0, rtol=1e-6)
    assert "props" in names and "target" in names  # the board stays put: once, outside groups


def test_colours_are_the_renderers_in_linear_space(tmp_path):
    env, infos = _flight("SGCThreeRods-v2")
    scenario = env.unwrapped.scenario
    glb = read_glb(write_glb(tmp_path / "c.glb", scenario, [motion_of("a", infos)]))
    for body in scenario.bodies:
        node = glb.doc["nodes"][glb.node_index(f"a/{body.name}")]
        material = glb.doc["meshes"][node["mesh"]]["primitives"][0]["material"]
        factor = glb.doc["materials"][material]["pbrMetallicRoughness"]["baseColorFactor"]
        np.testing.assert_allclose(factor, linear_color(body.color))
    assert linear_color((1.0, 0.5, 0.0, 1.0)) == pytest.approx([1.0, 0.21404, 0.0, 1.0], abs=1e-5)


def test_rods_are_drawn_as_thick_as_asked_never_thinner(tmp_path):
    env, infos = _flight("SGCRod-v1")
    scenario = env.unwrapped.scenario
    radius = scenario.bodies[0].size[1]
    for asked, expected in ((None, radius), (radius / 2, radius), (0.075, 0.075)):
        glb = read_glb(write_glb(tmp_path / "r.glb", scenario, [motion_of("a", infos)],
                                 rod_radius=asked))  # fmt: skip
        node = glb.doc["nodes"][glb.node_index(f"a/{scenario.bodies[0].name}")]
        position = glb.doc["meshes"][node["mesh"]]["primitives"][0]["attributes"]["POSITION"]
        extent = glb.doc["accessors"][position]["max"]
        assert extent[0] == pytest.approx(expected, rel=1e-6)
        assert extent[2] == pytest.approx(scenario.bodies[0].size[0] / 2, rel=1e-6)


@pytest.mark.parametrize(
    "mesh", [sphere_mesh(0.3), cylinder_mesh(0.04, 1.0), box_mesh((0.1, 3.0, 2.2))],
    ids=["sphere", "cylinder", "box"],
)  # fmt: skip
def test_meshes_face_outward_with_unit_normals(mesh):
    positions, normals, indices = mesh
    a, b, c = (positions[indices.reshape(-1, 3)[:, k]] for k in range(3))
    faces = np.cross(b - a, c - a)
    assert (np.linalg.norm(faces, axis=1) > 0).all()
    mean_normals = sum(normals[indices.reshape(-1, 3)[:, k]] for k in range(3))
    assert (np.sum(faces * mean_normals, axis=1) > 0).all()  # counter-clockwise from outside
    np.testing.assert_allclose(np.linalg.norm(normals, axis=1), 1.0)
    assert indices.max() < len(positions)


def _motion(bodies: int = 1, ticks: int = 3) -> Motion:
    orientation = np.tile([0.0, 0.0, 0.0, 1.0], (ticks, bodies, 1))
    return Motion("m", np.arange(ticks) / 60.0, np.zeros((ticks, bodies, 3)), orientation)


@pytest.mark.parametrize(
    "change, message",
    [
        ({"label": ""}, "label"),
        ({"times": np.array([0.0, 0.1, 0.1])}, "times: must increase"),
        ({"times": np.array([0.0, np.nan, 0.2])}, "times"),
        ({"positions": np.zeros((3, 2, 3))}, r"positions: expected shape \(3, 1, 3\)"),
        ({"positions": np.full((3, 1, 3), np.inf)}, "positions: not finite"),
        ({"orientations": np.zeros((3, 1, 4))}, "a zero quaternion"),
        ({"prop_positions": np.zeros((3, 5, 3))}, "prop_positions: expected shape"),
    ],
)
def test_a_bad_motion_is_refused_naming_its_field(change, message):
    env = gym.make("SGCPoint-v1")
    env.reset(seed=0)
    scenario = env.unwrapped.scenario
    motion = dataclasses.replace(_motion(), **change)
    with pytest.raises(ValueError, match=message):
        glb_bytes(scenario, [motion])


def test_no_motion_twice_a_label_or_a_bad_radius_is_refused():
    env = gym.make("SGCPoint-v1")
    env.reset(seed=0)
    scenario = env.unwrapped.scenario
    with pytest.raises(ValueError, match="at least one motion"):
        glb_bytes(scenario, [])
    with pytest.raises(ValueError, match="labels must differ"):
        glb_bytes(scenario, [_motion(), _motion()])
    with pytest.raises(ValueError, match="rod_radius"):
        glb_bytes(scenario, [_motion()], rod_radius=float("nan"))
    with pytest.raises(ValueError, match="an info without 'body_position'"):
        motion_of("m", [{"time": 0.0}])
    with pytest.raises(ValueError, match="got none"):
        motion_of("m", [])


def test_the_size_cap_is_checked_before_any_work(monkeypatch):
    env = gym.make("SGCPoint-v1")
    env.reset(seed=0)
    monkeypatch.setattr(gltf, "MAX_GLB_BYTES", 1 << 20)

    def no_work(*args: object, **kwargs: object) -> None:
        raise AssertionError("built a file over the cap")

    monkeypatch.setattr(gltf._Builder, "build", no_work)
    with pytest.raises(ValueError, match="MiB cap"):
        glb_bytes(env.unwrapped.scenario, [_motion(ticks=50_000)])


def test_same_flight_same_bytes():
    env, infos = _flight("SGCRod-v1")
    one = glb_bytes(env.unwrapped.scenario, [motion_of("a", infos)])
    env2, infos2 = _flight("SGCRod-v1")
    assert one == glb_bytes(env2.unwrapped.scenario, [motion_of("a", infos2)])


def test_the_viewer_page_ships_with_the_package(tmp_path):
    page = gltf.write_viewer(tmp_path, "rollout.glb")
    text = page.read_text()
    assert page.name == "viewer.html" and "GLTFLoader" in text
    assert '|| "rollout.glb";' in text and "three_rods.glb\";" not in text
    for bad in ("../x.glb", "x.png", 'a".glb'):
        with pytest.raises(ValueError, match="viewer: expected a .glb file name"):
            gltf.write_viewer(tmp_path, bad)
    assert sgc_env  # the ids above are registered by importing the package
