"""env.render(): the demo's look at 640x480, a camera that keeps the scene in frame, videos."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import sgc_env  # noqa: F401  (registers the ids)
from baselines.controllers.expert import SGCExpert
from sgc_env.envs import SGCEnv

WATCHED = ("SGCRod-v1", "SGCThreeRods-v2", "SGCIntercept-v1")


def _largest_colour_share(frame: np.ndarray) -> float:
    _, counts = np.unique(frame.reshape(-1, 3), axis=0, return_counts=True)
    return float(counts.max() / counts.sum())


def _assert_watchable(path, frames: int) -> None:
    """The mp4 decodes to at least ``frames`` frames, none of them mostly one colour."""
    import imageio.v2 as imageio

    decoded = imageio.mimread(path, memtest=False)
    assert len(decoded) >= frames
    assert max(_largest_colour_share(f[:, :, :3]) for f in decoded) < 0.5


@pytest.mark.parametrize("env_id", WATCHED)
def test_frame_is_640x480_and_no_colour_covers_half_of_it(env_id):
    env = gym.make(env_id, render_mode="rgb_array")
    env.reset(seed=0)
    for _ in range(10):
        env.step(env.action_space.sample() * 0.0)
    frame = env.render()
    env.close()
    assert frame.shape == (480, 640, 3) and frame.dtype == np.uint8
    assert _largest_colour_share(frame) < 0.5


def _expert_positions(env_id: str, camera: str = "fixed"):
    """Each step's camera (without painting) and body positions along an expert episode."""
    env = gym.make(env_id, render_mode="rgb_array", camera=camera, width=320, height=240)
    base = env.unwrapped
    expert = SGCExpert(env)
    obs, info = env.reset(seed=0)
    out = []
    done = False
    while not done:
        out.append((base.camera_view(), np.asarray(info["body_position"], float)))
        obs, _, terminated, truncated, info = env.step(expert.predict(obs, deterministic=True)[0])
        done = terminated or truncated
    env.close()
    return out


@pytest.mark.parametrize("env_id", WATCHED)
def test_every_body_stays_in_frame_of_the_fixed_camera(env_id):
    for view, positions in _expert_positions(env_id):
        px, depth = view.project(positions)
        assert np.all(depth > 0.0)
        assert np.all((px >= 0.0) & (px <= [view.width, view.height])), px


def test_tracking_camera_follows_the_bodies():
    frames = _expert_positions("SGCThreeRods-v2", camera="tracking")
    looks = {view.orbit[0] for view, _ in frames}
    assert len(looks) > len(frames) // 2  # it moves
    for view, positions in frames:
        px, _ = view.project(positions)
        assert np.all((px >= 0.0) & (px <= [view.width, view.height]))


def test_width_and_height_set_the_frame():
    env = gym.make("SGCPoint-v1", render_mode="rgb_array", width=96, height=64)
    env.reset(seed=0)
    assert env.render().shape == (64, 96, 3)
    env.step(env.action_space.sample())
    assert env.render().shape == (64, 96, 3)
    env.close()


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"width": 0}, "width: expected 16 to"),
        ({"height": 10**6}, "height: expected 16 to"),
        ({"width": 64.5}, "width: expected an integer"),
        ({"height": True}, "height: expected an integer"),
        ({"camera": {"zoom": 2}}, "camera: unknown option"),
        ({"camera": {"width": 2}}, "frame size is width="),
        ({"camera": "orbiting"}, "camera: mode must be one of"),
        ({"camera": {"target": (0, 0, 1)}}, "target and distance together"),
        ({"camera": {"target": (0, 1), "distance": 2.0}}, "target must be 3 finite"),
        ({"camera": {"fov": 0}}, "fov must be"),
    ],
)
def test_bad_render_arguments_are_rejected(kwargs, message):
    with pytest.raises(ValueError, match=message):
        SGCEnv("point_three_goals", **kwargs)


def test_explicit_camera_looks_at_its_target():
    env = SGCEnv("point_three_goals", render_mode="rgb_array", width=80, height=60,
                 camera={"target": (0.5, 0.5, 1.1), "distance": 1.5})  # fmt: skip
    env.reset()
    view = env.camera_view()
    px, depth = view.project(np.array([[0.5, 0.5, 1.1]]))
    np.testing.assert_allclose(px[0], [40.0, 30.0], atol=1e-3)
    assert depth[0] == pytest.approx(1.5, rel=1e-6)
    env.close()


def test_rendering_changes_neither_physics_nor_saved_states():
    """The render world is a client of its own: a render between save and restore is fine."""
    plain, shown = SGCEnv("rod_basic"), SGCEnv("rod_basic", render_mode="rgb_array", width=64,
                                                height=48)  # fmt: skip
    plain.reset()
    shown.reset()
    saved = shown.save_state()
    shown.render()
    a = np.full(6, 0.1, np.float32)
    for _ in range(20):
        o1 = plain.step(a)[0]
        o2 = shown.step(a)[0]
        shown.render()
    assert o1.tobytes() == o2.tobytes()
    shown.restore_state(saved)
    for _ in range(20):
        o3 = shown.step(a)[0]
    assert o3.tobytes() == o1.tobytes()
    plain.close()
    shown.close()


def test_same_seed_same_frames():
    frames = []
    for _ in range(2):
        env = gym.make("SGCIntercept-v1", render_mode="rgb_array", width=64, height=48)
        env.reset(seed=3)
        for _ in range(5):
            env.step(np.full(3, 0.2, np.float32))
        frames.append(env.render())
        env.close()
    assert np.array_equal(frames[0], frames[1])


def test_human_mode_without_a_display_is_a_clear_error(monkeypatch):
    monkeypatch.delenv("DISPLAY", raising=False)
    with pytest.raises(RuntimeError, match="needs a display"):
        SGCEnv("point_three_goals", render_mode="human")


def test_record_video_writes_an_expert_episode(tmp_path):
    from gymnasium.wrappers import RecordVideo

    env = gym.make("SGCIntercept-v1", render_mode="rgb_array", width=160, height=120)
    env = RecordVideo(
        env, str(tmp_path / "videos"), episode_trigger=lambda _: True, disable_logger=True
    )
    expert = SGCExpert(env)
    obs, _ = env.reset(seed=0)
    done = False
    while not done:
        obs, _, terminated, truncated, _ = env.step(expert.predict(obs, deterministic=True)[0])
        done = terminated or truncated
    env.close()
    videos = list((tmp_path / "videos").glob("*.mp4"))
    assert len(videos) == 1
    _assert_watchable(videos[0], frames=env.unwrapped.max_steps)  # the whole episode


def test_sb3_video_recorder_as_rl_zoo3_uses_it(tmp_path):
    """rl-zoo3's ``record_video`` makes the env with ``render_mode="rgb_array"`` and wraps the
    vector env in SB3's ``VecVideoRecorder``: the same path, without a zoo model folder."""
    from stable_baselines3.common.vec_env import DummyVecEnv, VecVideoRecorder

    venv = DummyVecEnv([lambda: gym.make("SGCIntercept-v1", render_mode="rgb_array", width=160,
                                         height=120)])  # fmt: skip
    venv = VecVideoRecorder(venv, str(tmp_path), record_video_trigger=lambda step: step == 0,
                            video_length=30, name_prefix="zoo")  # fmt: skip
    venv.reset()
    for _ in range(31):
        venv.step(np.zeros((1, 3), np.float32))
    venv.close()
    videos = list(tmp_path.glob("zoo*.mp4"))
    assert len(videos) == 1
    _assert_watchable(videos[0], frames=30)


def test_env_checkers_pass_with_rendering():
    import warnings

    from gymnasium.utils.env_checker import check_env
    from stable_baselines3.common.env_checker import check_env as sb3_check_env

    env = gym.make("SGCRod-v1", render_mode="rgb_array", width=64, height=48)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_env(env.unwrapped, skip_render_check=False)
        sb3_check_env(env.unwrapped)
    env.close()


def test_a_rendered_env_pickles_and_renders_again():
    import pickle

    env = SGCEnv("rod_basic", render_mode="rgb_array", width=64, height=48, camera="tracking")
    env.reset()
    env.step(np.full(6, 0.1, np.float32))
    first = env.render()
    copy = pickle.loads(pickle.dumps(env))
    assert (copy.width, copy.height, copy.camera.mode) == (64, 48, "tracking")
    assert np.array_equal(copy.render(), first)
    env.close()
    copy.close()
