"""Each rule written once gives the same bits on floats (one env) and on arrays (the batched
env): the quaternion helpers on every branch (flipped and identity quaternions, tiny and
wrapped rotation vectors), the reward's track costs with goals ahead and behind, the effort's
sum, the measurement, actuation and failure rules."""

from __future__ import annotations

import numpy as np
import pytest

from sgc_env.envs.actuation import body_drive
from sgc_env.envs.failure import body_flags
from sgc_env.envs.measure import measure
from sgc_env.envs.rewards import schedule_error, square_sum, tracking_score
from sgc_env.paper import quaternion


def _quaternions(rng: np.random.Generator, n: int) -> np.ndarray:
    q = rng.normal(size=(n, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    q[: n // 8] = (0.0, 0.0, 0.0, 1.0)  # identity: the log's small-angle branch
    q[n // 8 : n // 4] = (0.0, 0.0, 0.0, -1.0)
    q[n // 4 : n // 4 + 4, :3] *= 1e-14  # vector part below 1e-12, not zero
    return q


def _cols(a: np.ndarray) -> tuple:
    return tuple(np.moveaxis(a, -1, 0))


def _same(columns: tuple, rows: list) -> None:
    """Array results (one array per component) equal the per-row float results, sign bits
    and NaNs included."""
    got = np.stack(np.broadcast_arrays(*columns), axis=-1)
    want = np.array(rows, dtype=float)
    assert np.array_equal(got, want, equal_nan=True)
    assert np.array_equal(np.signbit(got), np.signbit(want))


def test_quaternion_helpers_on_arrays_equal_the_float_ones() -> None:
    rng = np.random.default_rng(0)
    a, b = _quaternions(rng, 64), _quaternions(rng, 64)[::-1]
    v = rng.normal(size=(64, 3))
    rows = list(zip(a.tolist(), b.tolist(), v.tolist(), strict=True))
    with np.errstate(all="ignore"):
        _same(quaternion.rotate(_cols(a), _cols(v)), [quaternion.rotate(p, u) for p, _, u in rows])
        _same(quaternion.rotate_back(_cols(a), _cols(v)),
              [quaternion.rotate_back(p, u) for p, _, u in rows])  # fmt: skip
        _same(quaternion.mul_conjugate(_cols(a), _cols(b)),
              [quaternion.mul_conjugate(p, q) for p, q, _ in rows])  # fmt: skip
        _same(quaternion.log(_cols(a)), [quaternion.log(p) for p, _, _ in rows])


@pytest.mark.parametrize("scale", [0.0, 1e-13, 0.3, 3.0, 40.0])
def test_unwrap_on_arrays_equals_the_float_one(scale: float) -> None:
    rng = np.random.default_rng(1)
    principal = rng.normal(size=(64, 3))
    principal *= np.pi * rng.uniform(0, 1, (64, 1)) / np.linalg.norm(principal, axis=1)[:, None]
    principal[:8] *= 1e-13  # the identity: the axis comes from the reference
    reference = principal * scale + rng.normal(0, 0.1, (64, 3)) * (scale > 1e-12)
    reference[:4] = rng.normal(0, 5.0, (4, 3))  # |reference| >= pi with a tiny principal
    reference[60:] = -7.0 * principal[60:]  # a somersault the other way
    with np.errstate(all="ignore"):
        out = quaternion.unwrap_rotvec(_cols(principal), _cols(reference))
    pairs = zip(principal.tolist(), reference.tolist(), strict=True)
    _same(out, [quaternion.unwrap_rotvec(p, r) for p, r in pairs])


@pytest.mark.parametrize("cost", [schedule_error, tracking_score])
def test_track_costs_on_arrays_equal_the_float_ones(cost) -> None:
    rng = np.random.default_rng(2)
    d = rng.normal(0, 0.3, (64, 6))
    course = rng.normal(0, 0.2, (64, 13))
    course[:, 3] = rng.uniform(0.1, 2.0, 64)
    course[:8, :3] = 0.0  # below the floor
    left = rng.uniform(-1.0, 1.0, 64)
    left[:4] = 0.0
    for rows in (slice(None), left >= 0.0, left < 0.0):  # mixed, all ahead, all behind
        with np.errstate(all="ignore"):
            got = cost(_cols(d[rows]), left[rows], _cols(course[rows]), 0.1)
        want = [
            cost(a, t, c, 0.1)
            for a, t, c in zip(d[rows].tolist(), left[rows].tolist(), course[rows].tolist(),
                               strict=True)
        ]  # fmt: skip
        assert got.tolist() == want


def test_numpy_scalars_take_the_float_path() -> None:
    """Course entries can be numpy scalars (a track's end velocity); a cost of one env stays a
    Python float, as rewards are."""
    course = [np.float64(x) for x in (0.3, -0.2, 0.1, 1.0, 0, 0, 0, 0, 0.5, 0.1, -0.3, 1, 1)]
    for left in (0.4, -0.7):
        assert type(schedule_error((0.1, 0.2, 0.3), left, course, 0.1)) is float
        assert type(tracking_score((0.1, 0.2, 0.3), left, course, 0.1)) is float


def test_square_sum_sums_as_pythons_sum() -> None:
    actions = np.random.default_rng(3).uniform(-1, 1, (64, 18)).astype(np.float32).astype(float)
    assert square_sum(actions).tolist() == [square_sum(row) for row in actions.tolist()]


def _states(rng: np.random.Generator, n: int) -> np.ndarray:
    s = rng.normal(0, 2.0, (n, 13))
    s[:, 3:7] = _quaternions(rng, n)
    s[:4, 7:10] = 95.0  # too fast
    s[4:6, 10:13] = 80.0  # spin clamped
    s[6, 0] = np.nan
    return s


def _parts(s: np.ndarray) -> tuple:
    c = _cols(s)
    return c[0:3], c[3:7], c[7:10], c[10:13]


def test_measure_wrench_and_flags_on_arrays_equal_the_float_ones() -> None:
    rng = np.random.default_rng(4)
    n = 64
    s = _states(rng, n)
    offset = rng.normal(0, 0.3, (n, 3))
    has_offset = rng.uniform(size=n) < 0.7
    offset[~has_offset] = 0.0
    nail, goal_q, phi = rng.normal(size=(n, 3)), _quaternions(rng, n), rng.normal(size=(n, 3))
    has_pos, has_ori = rng.uniform(size=n) < 0.8, rng.uniform(size=n) < 0.6
    ptime, otime = rng.uniform(0, 3, n), rng.uniform(0, 3, n)
    action, limit = rng.uniform(-1, 1, (n, 6)), rng.uniform(1, 9, n)
    scale = rng.uniform(size=(n, 3))
    low, high = np.full((n, 3), -5.0), np.full((n, 3), 5.0)
    with np.errstate(all="ignore"):
        got = measure(
            _parts(s), 0.5, _cols(offset), has_offset, _cols(nail), has_pos, ptime,
            _cols(goal_q), has_ori, otime, _cols(phi),
        )  # fmt: skip
        mass = rng.uniform(0.5, 2.0, n)
        coef = [(k / 240, k * (k + 1) / 2 / 240**2) for k in range(4)]
        wrench = body_drive(
            _cols(action), _parts(s)[0], _cols(s[:, 3:7]), _parts(s)[2], limit, _cols(scale), mass,
            (0.0, 0.0, -9.81), coef,
        )  # fmt: skip
        flags = body_flags(_parts(s), _cols(low), _cols(high))
    rows = [
        measure(
            _parts(np.array(s[i].tolist())), 0.5, tuple(offset[i].tolist()), bool(has_offset[i]),
            tuple(nail[i].tolist()), bool(has_pos[i]), float(ptime[i]),
            tuple(goal_q[i].tolist()), bool(has_ori[i]), float(otime[i]), tuple(phi[i].tolist()),
        )
        for i in range(n)
    ]  # fmt: skip
    rows = [
        (*(float(x) for x in r[0]), *r[1], float(r[2]), *(float(x) for x in r[3]), float(r[4]))
        for r in rows
    ]
    _same((*got[0], *got[1], got[2], *got[3], got[4]), rows)
    wrenches = [
        body_drive(
            action[i].tolist(), s[i, 0:3].tolist(), s[i, 3:7].tolist(), s[i, 7:10].tolist(),
            float(limit[i]), scale[i].tolist(), float(mass[i]), (0.0, 0.0, -9.81), coef,
        )
        for i in range(n)
    ]  # fmt: skip
    _same(
        (*wrench[0], *wrench[1], *(x for p in wrench[2] for x in p)),
        [(*f, *t, *(x for p in path for x in p)) for f, t, path in wrenches],
    )
    single = [
        body_flags(_parts(np.array(s[i].tolist())), low[i].tolist(), high[i].tolist())
        for i in range(n)
    ]
    assert flags[0].tolist() == [bool(ok) for ok, _ in single]
    assert flags[1].tolist() == [bool(c) for _, c in single]
    assert 0 < flags[0].sum() < n and flags[1].any()  # every branch taken
