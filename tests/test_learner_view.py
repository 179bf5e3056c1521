"""The learner's view: bounded, float32, and the on-schedule features an independent reading
of the planner's view gives."""

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


def _on_schedule_reference(obs: np.ndarray, layout, track: str) -> np.ndarray:
    """Error and rate against the schedule (squashed, scales 0.05 and 0.5), the schedule's
    velocity and the next course's (squashed), from the planner's view in float64: an
    independent reading of the same rule (docs/environments.md)."""
    rate_field = "point_velocity" if track == "position" else "angular_velocity"

    def get(name: str) -> np.ndarray:
        return obs[layout.body_slice(0, name)].astype(np.float64)

    deviation, rate = get(f"{track}_deviation"), get(rate_field)
    left, duration = get(f"{track}_time_left")[0], get(f"{track}_course_duration")[0]
    start, end = get(f"{track}_course_start"), get(f"{track}_end_velocity")
    next_start, next_duration = get(f"{track}_next_start"), get(f"{track}_next_duration")[0]
    in_course = left >= 0 and duration > 0
    schedule = start * left / duration if in_course else -end * left
    schedule_rate = -start / duration if in_course else end
    next_rate = -next_start / next_duration if next_duration > 0 else np.zeros(3)

    def squash(x: np.ndarray) -> np.ndarray:
        return 3.0 * np.tanh(x / 3.0)

    error, error_rate = (deviation - schedule) / 0.05, (rate - schedule_rate) / 0.5
    return np.concatenate([squash(error), squash(error_rate), squash(schedule_rate),
                           squash(next_rate)])  # fmt: skip


def test_on_schedule_entries_match_an_independent_reading_of_the_planner_view() -> None:
    """Error, rate and schedule velocities of both tracks equal a float64 reading of the
    float32 planner observation (so they agree to float32)."""
    env = gym.make("SGCRod-v1", observation="planner")
    obs, _ = env.reset(seed=3)
    layout = env.unwrapped.layout
    for _ in range(60):
        obs, *_ = env.step(env.action_space.sample() * 0.2)
        view = learner_observation(env.unwrapped._block[None], np.zeros((1, 1, 3)),
                                   np.zeros(1))[0]  # fmt: skip
        np.testing.assert_allclose(view[0:12], _on_schedule_reference(obs, layout, "position"),
                                   atol=2e-4)  # fmt: skip
        o = LEARNER_TRACK_SIZE
        np.testing.assert_allclose(view[o : o + 12],
                                   _on_schedule_reference(obs, layout, "orientation"), atol=2e-4)
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
