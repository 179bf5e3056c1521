"""``on_schedule``: one env's float branch and the batch's array branch give the same bits."""

from __future__ import annotations

import numpy as np
import pytest

from sgc_env.envs.schedule import on_schedule


def _cases(rng: np.random.Generator, n: int) -> tuple[np.ndarray, ...]:
    start = rng.normal(size=(n, 3))
    end_velocity = rng.normal(size=(n, 3))
    span = np.where(rng.random(n) < 0.2, 0.0, rng.uniform(0.01, 3.0, n))
    left = np.where(rng.random(n) < 0.3, -rng.uniform(0.0, 2.0, n), rng.uniform(0.0, 3.0, n))
    left[:3] = [0.0, -0.0, 1e-300]  # the course's own end and its neighbours
    return start, end_velocity, span, left


def test_floats_and_arrays_agree_bit_for_bit() -> None:
    start, end_velocity, span, left = _cases(np.random.default_rng(7), 400)
    deviation, rate, running, fraction = on_schedule(
        list(start.T), span, list(end_velocity.T), left
    )
    for i in range(len(left)):
        d, r, on, f = on_schedule(
            start[i].tolist(), float(span[i]), end_velocity[i].tolist(), float(left[i])
        )
        assert type(on) is bool and on == bool(running[i])
        assert np.array([*d, *r, f]).tobytes() == np.array(
            [*(x[i] for x in deviation), *(x[i] for x in rate), fraction[i]]
        ).tobytes(), f"case {i}: span {span[i]}, left {left[i]}"


@pytest.mark.parametrize(("span", "left", "running"), [(2.0, 0.5, True), (2.0, -0.5, False),
                                                       (0.0, 0.5, False)])  # fmt: skip
def test_the_rule(span: float, left: float, running: bool) -> None:
    d, r, on, f = on_schedule([1.0, -2.0, 4.0], span, [0.5, 0.0, -1.0], left)
    assert on is running
    if running:
        assert (d, r, f) == ([0.25, -0.5, 1.0], [-0.5, 1.0, -2.0], 0.25)
    else:  # past the course's end: on at the goal's end velocity
        assert (d, r) == ([-0.5 * left, -0.0 * left, 1.0 * left], [0.5, 0.0, -1.0])
        assert f == (left / span if span > 0.0 else left)
