"""rgb_array rendering through the TinyRenderer (headless)."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import sgc_env  # noqa: F401  (registers the ids)
from sgc_env.envs import SGCEnv


@pytest.mark.parametrize("env_id", ["SGCPoint-v0", "SGCThreeRods-v0"])
def test_rgb_array_has_declared_shape(env_id):
    env = gym.make(env_id, render_mode="rgb_array", camera={"width": 96, "height": 64})
    env.reset(seed=0)
    frame = env.render()
    assert frame.shape == (64, 96, 3) and frame.dtype == np.uint8
    env.step(env.action_space.sample())
    assert env.render().shape == (64, 96, 3)
    env.close()


def test_body_and_markers_are_visible():
    env = SGCEnv(
        "point_three_goals", render_mode="rgb_array",
        camera={"distance": 1.5, "target": (0.5, 0.5, 1.1), "width": 80, "height": 60},
    )  # fmt: skip
    env.reset()
    frame = env.render()
    background = frame[0, 0]
    assert np.any(np.any(frame != background, axis=-1))


def test_markers_do_not_change_physics():
    plain, shown = SGCEnv("rod_basic"), SGCEnv("rod_basic", render_mode="rgb_array")
    plain.reset()
    shown.reset()
    shown.render()
    a = np.full(6, 0.1, np.float32)
    for _ in range(20):
        o1 = plain.step(a)[0]
        o2 = shown.step(a)[0]
    assert o1.tobytes() == o2.tobytes()


def test_bad_camera_option_is_rejected():
    with pytest.raises(ValueError, match="camera: unknown option"):
        SGCEnv("point_three_goals", camera={"zoom": 2})
