"""The learner's view: bounded, float32, and the same on-schedule features the policy-side
extractor computes (an independent implementation in torch,
:mod:`baselines.models.schedule_features`)."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import sgc_env  # noqa: F401
from sgc_env.envs.learner_view import (
    LEARNER_BODY_SIZE,
    LEARNER_TRACK_SIZE,
    learner_bounds,
    learner_observation,
    learner_size,
)


def _records(env_id: str, steps: int, seed: int = 0) -> list[np.ndarray]:
    """The planner's double-precision record after each of ``steps`` random-action steps."""
    env = gym.make(env_id)
    env.reset(seed=seed)
    env.action_space.seed(seed)
    out = [env.unwrapped._block.copy()]
    for _ in range(steps):
        _, _, terminated, truncated, _ = env.step(env.action_space.sample() * 0.3)
        out.append(env.unwrapped._block.copy())
        if terminated or truncated:
            env.reset()
    env.close()
    return out


@pytest.mark.parametrize("env_id", ["SGCPoint-v1", "SGCRod-v1", "SGCThreeRodsRandom-v3"])
def test_view_is_float32_inside_its_bounds(env_id: str) -> None:
    blocks = np.stack(_records(env_id, 120))
    n_bodies = blocks.shape[1]
    hover = np.tile([0.0, 0.0, 0.4], (len(blocks), n_bodies, 1))
    fraction = np.linspace(0.0, 1.0, len(blocks))
    view = learner_observation(blocks, hover, fraction)
    low, high = learner_bounds(n_bodies)
    assert view.dtype == np.float32 and view.shape == (len(blocks), learner_size(n_bodies))
    assert np.all(np.isfinite(view))
    assert np.all(view >= low) and np.all(view <= high)
    assert np.all(np.abs(low) <= 3.0) and np.all(np.abs(high) <= 3.0)


def test_on_schedule_entries_match_the_policy_side_extractor() -> None:
    """Error, rate and schedule velocities of the position track equal ScheduleFeatures' (the
    torch extractor reads the float32 planner observation, so they agree to float32)."""
    th = pytest.importorskip("torch")
    from baselines.models.schedule_features import ScheduleFeatures

    env = gym.make("SGCRod-v1")
    obs, _ = env.reset(seed=3)
    rows, views = [], []
    for _ in range(60):
        obs, *_ = env.step(env.action_space.sample() * 0.2)
        rows.append(obs)
        views.append(learner_observation(env.unwrapped._block[None], np.zeros((1, 1, 3)),
                                         np.zeros(1))[0])  # fmt: skip
    extractor = ScheduleFeatures(env.observation_space, gravity=0.0, squash=3.0)
    with th.no_grad():
        features = extractor(th.as_tensor(np.stack(rows))).numpy()
    mine = np.stack(views)
    # ScheduleFeatures: error 3, rate 3 (squashed), schedule rate 3, next rate 3 (not squashed)
    for start in (6, 22):
        features[:, start : start + 6] = 3.0 * np.tanh(features[:, start : start + 6] / 3.0)
    np.testing.assert_allclose(mine[:, 0:12], features[:, 0:12], atol=2e-4)
    o = LEARNER_TRACK_SIZE
    np.testing.assert_allclose(mine[:, o : o + 12], features[:, 16:28], atol=2e-4)
    env.close()


def test_goal_preview_points_from_the_body_to_the_nails() -> None:
    """The current goal entry is the nail minus the tracked point (squashed), the next goal's
    the next nail minus the point, with the goal times."""
    env = gym.make("SGCPoint-v1")
    env.reset(seed=5)
    task = env.unwrapped.task
    view = learner_observation(env.unwrapped._block[None], np.zeros((1, 1, 3)), np.zeros(1))[0]
    track = task.tracks[0].position
    point = np.array(task.points[0])
    k = task.pos_idx[0]
    expected = 3.0 * np.tanh((track.targets[k] - point) / 3.0)
    np.testing.assert_allclose(view[12:15], expected, atol=1e-6)
    expected_next = 3.0 * np.tanh((track.targets[k + 1] - point) / 3.0)
    np.testing.assert_allclose(view[15:18], expected_next, atol=1e-6)
    left = track.times[k] - task.time
    np.testing.assert_allclose(view[19:21], [left, left + track.durations[k + 1]], atol=1e-6)
    assert LEARNER_BODY_SIZE * 1 + 1 == len(view)
    env.close()


def test_bad_record_shape_is_refused() -> None:
    with pytest.raises(ValueError, match="expected"):
        learner_observation(np.zeros((2, 5)), np.zeros((2, 1, 3)), np.zeros(2))
