"""One env's learner view (floats, per-course terms cached) equals the array path bit for bit:
on real episodes of every learner id (goal switches, courses run past their end, tracks a body
lacks, resets onto new scenes), on course entries that differ only in the sign of a zero, and
where it hands over to the array path (a strided or float32 record, writable constants)."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import sgc_env
from sgc_env.envs.learner_view import LearnerView, _course_terms
from sgc_env.observation import ObservationLayout

# Random three-rod scenes cost ~0.2 s per reset: a shorter run.
STEPS = {"SGCThreeRodsRandom-v3": 250}


def _array_path(view: LearnerView, record: np.ndarray, constants: np.ndarray) -> np.ndarray:
    """The batch's rule on one row: what every sub-env of the batched env gets."""
    return view.observe(record[None], constants[None])[0]


def _bits(a: np.ndarray) -> bytes:
    assert a.dtype == np.float32
    return a.tobytes()


def _hover(env: gym.Env) -> np.ndarray:
    """The action that holds every body up: an episode that runs past its last goal (the
    courses' end velocity), where random actions fail early."""
    base = env.unwrapped
    hover = np.clip(base._view_constants[:-1], -1.0, 1.0)
    action = np.zeros(env.action_space.shape)
    per_body = action.size // (hover.size // 3)
    for j in range(hover.size // 3):
        action[j * per_body : j * per_body + 3] = hover[3 * j : 3 * j + 3]
    return action


@pytest.mark.parametrize("env_id", sgc_env.ENV_IDS)
def test_one_env_equals_the_array_path_on_real_episodes(env_id: str) -> None:
    env = gym.make(env_id)
    base = env.unwrapped
    view = base._view
    if not isinstance(view, LearnerView):
        pytest.skip(f"{env_id} does not hand out the learner view")
    rng = np.random.default_rng(3)
    env.reset(seed=3)
    env.action_space.seed(3)
    hover, past_end, episodes = _hover(env), 0, 0
    for _ in range(STEPS.get(env_id, 600)):
        action = hover if episodes == 0 else env.action_space.sample() * 1.2
        obs, *_, terminated, truncated, _ = env.step(action)
        record = np.append(base._block, base._tick * base.dt)
        constants = base._view_constants
        one = view.observe(record, constants)
        assert _bits(one) == _bits(_array_path(view, record, constants))
        if isinstance(obs, np.ndarray):
            assert _bits(obs) == _bits(one)
        task = base.task
        past_end += min(task.position_time_left + task.orientation_time_left) < 0.0
        if terminated or truncated:
            episodes += 1
            env.reset(seed=int(rng.integers(1000)))
    env.close()
    assert episodes >= 1
    if "ThreeRods" not in env_id:  # held three-rod scenes fail before their end
        assert past_end


def _rod_record() -> tuple[LearnerView, np.ndarray, np.ndarray]:
    env = gym.make("SGCRod-v1")
    env.reset(seed=0)
    for _ in range(5):
        env.step(env.action_space.sample() * 0.0)
    base = env.unwrapped
    record = np.append(base._block, base._tick * base.dt)
    view, constants = base._view, base._view_constants
    env.close()
    return view, record, constants


def test_a_course_that_differs_only_in_the_sign_of_a_zero_is_a_new_course() -> None:
    view, record, constants = _rod_record()
    layout = ObservationLayout(1)
    start = layout.body_slice(0, "position_course_start").start
    view.observe(record, constants)  # caches the course
    for signed in (-0.0, 0.0, -0.0):
        edited = record.copy()
        edited[start] = signed  # 0.0 == -0.0: only the bytes tell the courses apart
        one = view.observe(edited, constants)
        assert _bits(one) == _bits(_array_path(view, edited, constants))


def test_records_the_float_path_cannot_read_take_the_array_path() -> None:
    view, record, constants = _rod_record()
    expected = _bits(_array_path(view, record, constants))
    strided = np.repeat(record, 2)[::2]  # the same values, not contiguous
    assert _bits(view.observe(strided, constants)) == expected
    writable = constants.copy()  # a writable array is read again every call
    assert _bits(view.observe(record, writable)) == expected
    writable[0] = 0.5
    assert _bits(view.observe(record, writable)) == _bits(_array_path(view, record, writable))
    narrow = record.astype(np.float32)
    assert _bits(view.observe(narrow, constants)) == _bits(_array_path(view, narrow, constants))


def test_the_constants_a_view_hands_out_are_read_only() -> None:
    env = gym.make("SGCPoint-v1")
    env.reset(seed=0)
    assert not env.unwrapped._view_constants.flags.writeable
    env.close()


def test_course_terms_are_the_rules_terms() -> None:
    """Spot check of the cached terms against the rule's own arithmetic."""
    course = [0.3, -0.2, 0.1, 1.5, -0.4, 0.0, 0.2, 0.5, 0.1, 0.2, -0.3, 1.0, 0.0]
    terms = _course_terms(course)
    c0, span, v_end, next_rate, has_next, *c1, next_span, has, last = terms
    assert (c0, span, v_end) == ([0.3, -0.2, 0.1], 1.5, [0.1, 0.2, -0.3])
    assert next_rate == (0.4 / 0.5, -0.0 / 0.5, -0.2 / 0.5)
    assert (has_next, c1, next_span, has, last) == (True, [-0.4, 0.0, 0.2], 0.5, 1.0, 0.0)
    alone = _course_terms([*course[:4], 0.0, 0.0, 0.0, 0.0, *course[8:]])
    assert alone[3:5] == ((0.0, 0.0, 0.0), False)  # no next course: no next velocity
