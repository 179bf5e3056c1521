"""The batched task's array arithmetic equals the scalar helpers bit for bit on every branch:
flipped and identity quaternions, tiny and wrapped rotation vectors, goals ahead and behind."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from sgc_env.envs import batch_math as bm
from sgc_env.envs.batch_task import BatchTask
from sgc_env.envs.rewards import _effort, distance_cost, schedule_cost
from sgc_env.paper import quaternion


def _quaternions(rng: np.random.Generator, n: int) -> np.ndarray:
    q = rng.normal(size=(n, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    q[: n // 8] = (0.0, 0.0, 0.0, 1.0)  # identity: the log's small-angle branch
    q[n // 8 : n // 4] = (0.0, 0.0, 0.0, -1.0)
    q[n // 4 : n // 4 + 4, :3] *= 1e-14  # vector part below 1e-12, not zero
    return q


def _same(array: np.ndarray, scalar: list[tuple[float, ...]]) -> None:
    assert np.array_equal(array, np.array(scalar), equal_nan=True)
    assert np.array_equal(np.signbit(array), np.signbit(np.array(scalar)))


def test_quaternion_helpers_on_arrays_equal_the_scalar_ones() -> None:
    rng = np.random.default_rng(0)
    a, b = _quaternions(rng, 64), _quaternions(rng, 64)[::-1]
    v = rng.normal(size=(64, 3))
    back = a * np.array([-1.0, -1.0, -1.0, 1.0])
    with np.errstate(all="ignore"):
        _same(bm.rotate(a, v), [quaternion.rotate(p, u) for p, u in zip(a, v, strict=True)])
        _same(bm.rotate(back, v), [quaternion.rotate_back(p, u) for p, u in zip(a, v, strict=True)])
        _same(bm.mul_conjugate(a, bm.conjugate_factors(b)),
              [quaternion.mul_conjugate(p, q) for p, q in zip(a, b, strict=True)])  # fmt: skip
        _same(bm.log(a), [quaternion.log(p) for p in a])
        _same(bm.norm(v), [float(np.sqrt(x * x + y * y + z * z)) for x, y, z in v.tolist()])


@pytest.mark.parametrize("scale", [0.0, 1e-13, 0.3, 3.0, 40.0])
def test_unwrap_equals_the_scalar_one(scale: float) -> None:
    rng = np.random.default_rng(1)
    principal = rng.normal(size=(64, 3))
    principal *= np.pi * rng.uniform(0, 1, (64, 1)) / np.linalg.norm(principal, axis=1)[:, None]
    principal[:8] *= 1e-13  # the identity: the axis comes from the reference
    reference = principal * scale + rng.normal(0, 0.1, (64, 3)) * (scale > 1e-12)
    reference[:4] = rng.normal(0, 5.0, (4, 3))  # |reference| >= pi with a tiny principal
    reference[60:] = -7.0 * principal[60:]  # a somersault the other way
    with np.errstate(all="ignore"):
        out = bm.unwrap_rotvec(principal, reference)
    scalar = [quaternion.unwrap_rotvec(p, r) for p, r in zip(principal, reference, strict=True)]
    _same(out, scalar)


@pytest.mark.parametrize("mode", ["schedule", "distance"])
def test_track_costs_equal_the_scalar_ones(mode: str) -> None:
    rng = np.random.default_rng(2)
    d = rng.normal(0, 0.3, (64, 6))
    course = rng.normal(0, 0.2, (64, 13))
    course[:, 3] = rng.uniform(0.1, 2.0, 64)
    course[:8, :3] = 0.0  # below the floor
    left = rng.uniform(-1.0, 1.0, 64)
    left[:4] = 0.0
    for rows in (slice(None), left >= 0.0, left < 0.0):  # mixed, all ahead, all behind
        with np.errstate(all="ignore"):
            got = BatchTask._cost(
                SimpleNamespace(mode=mode), d[rows], left[rows], course[rows], 0.1
            )  # type: ignore[arg-type]
        cost = schedule_cost if mode == "schedule" else distance_cost
        want = [
            cost((a, t, c), 0.1) for a, t, c in zip(d[rows], left[rows], course[rows], strict=True)
        ]
        assert got.tolist() == want


def test_effort_sums_as_pythons_sum() -> None:
    actions = np.random.default_rng(3).uniform(-1, 1, (64, 18)).astype(np.float32).astype(float)
    got = BatchTask._effort(SimpleNamespace(), actions)  # type: ignore[arg-type]
    assert got.tolist() == [_effort(row) for row in actions.tolist()]
