"""The reset path's cheaper forms compute what the plain ones did: prop tables filled with one
``tolist()`` hold the floats a per-coordinate ``float()`` gave, and the three-rod builder's
plain-float goal alignment is scipy's ``Rotation`` composition."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from sgc_env.envs.props import CHUNK, PropPaths
from sgc_env.scenario import Prop
from sgc_env.scenes.three_rods import _align


def _direct(prop: Prop, j: int, frequency: int) -> tuple[float, float, float]:
    t = j / frequency
    if prop.waypoints:
        times = [w[0] for w in prop.waypoints]
        pts = np.asarray([w[1] for w in prop.waypoints])
        x, y, z = (float(np.interp(t, times, pts[:, k])) for k in range(3))
    else:
        x, y, z = (float(c) for c in np.asarray(prop.position) + t * np.asarray(prop.velocity))
    return x, y, z


def test_prop_chunks_hold_the_floats_of_a_direct_evaluation():
    props = (
        Prop("swim", waypoints=((0.0, (0.0, 1.0, 2.0)), (3.3, (1.7, -0.2, 0.9)))),
        Prop("fly", position=(0.1, 0.2, 0.3), velocity=(0.3, -1.1, 0.07)),
    )
    paths = PropPaths(props, 240, 3 * CHUNK)
    for j in (0, 1, CHUNK - 1, CHUNK, CHUNK + 7, 3 * CHUNK, 5 * CHUNK):
        row = paths.at(j)
        assert all(type(x) is float for x in row[0])  # plain floats, as PyBullet takes them
        assert row == [list(_direct(p, min(j, 3 * CHUNK), 240)) for p in props], j


@pytest.mark.parametrize("seed", range(5))
def test_goal_alignment_matches_scipy_rotations(seed):
    rng = np.random.default_rng(seed)
    previous_q = (0.0, 0.0, 0.0, 1.0)
    previous_r = Rotation.identity()
    for _ in range(30):
        tangent = rng.normal(size=3)
        previous_q = _align(previous_q, tangent)
        axis_now = previous_r.apply([0.0, 0.0, 1.0])
        t = tangent / np.linalg.norm(tangent)
        cross = np.cross(axis_now, t)
        angle = np.arctan2(np.linalg.norm(cross), axis_now @ t)
        previous_r = Rotation.from_rotvec(cross / np.linalg.norm(cross) * angle) * previous_r
        assert np.allclose(previous_q, previous_r.as_quat(), rtol=0, atol=1e-13)
        assert np.allclose(Rotation.from_quat(previous_q).apply([0, 0, 1]), t, atol=1e-12)


def _numpy_arc_length_samples(spline, bounds, counts, fine):
    """The three-rod sampler as numpy calls per stretch (what ``_arc_length_samples`` writes
    out for all stretches at once)."""
    out = []
    for s0, s1, count in zip(bounds[:-1], bounds[1:], counts, strict=True):
        grid = np.linspace(s0, s1, fine)
        pts = spline(grid)
        arc = np.concatenate(([0.0], np.cumsum(np.linalg.norm(np.diff(pts, axis=0), axis=1))))
        params = np.interp(arc[-1] * np.arange(1, count + 1) / count, arc, grid)
        params[-1] = grid[-1]
        out.append(params)
    return np.concatenate(out)


@pytest.mark.parametrize("k", range(3))
def test_the_written_out_arc_length_sampler_gives_numpys_floats(k):
    from sgc_env.scenes.three_rods import ROD_SPECS, _arc_length_samples, _spline

    rng = np.random.default_rng(k)
    base = np.asarray(ROD_SPECS[k].waypoints)
    for _ in range(5):
        points = base + rng.uniform(-0.4, 0.4, base.shape)
        spline, knots = _spline(points)
        chord = np.linalg.norm(np.diff(points, axis=0), axis=1)
        assert knots.tolist() == np.concatenate(([0.0], np.cumsum(chord))).tolist()
        bounds, counts = (knots[0], knots[1], knots[-1]), (3, 12)
        fast = _arc_length_samples(spline, bounds, counts, 401)
        assert fast.tobytes() == _numpy_arc_length_samples(spline, bounds, counts, 401).tobytes()


def _numpy_changes(velocities, before, after):
    steps = np.linalg.norm(np.diff(np.vstack((before, velocities, after)), axis=0), axis=1)
    return steps[:-1] + steps[1:]


def test_the_plain_float_course_bound_gives_numpys_floats():
    """``point_feature`` and ``spin_feature`` against their numpy formulation (the one before
    they were written out) on fresh three-rod candidates, somersaults included."""
    from sgc_env.scenes import course_bound
    from sgc_env.scenes import three_rods_random as family

    cfg = family.RandomThreeRodsConfig()
    rng = np.random.default_rng(8)
    rest = np.zeros(3)
    checked = 0
    for k in (0, 1, 1, 2):
        candidate = None
        while candidate is None:
            candidate = family._candidate(rng, k, cfg)
        c = candidate
        durations = np.diff(np.array([0.0, *c.times]))
        velocities = np.diff(np.vstack((c.tip, c.nails)), axis=0) / durations[:, None]
        point = float(np.max(_numpy_changes(velocities, c.path.launch, rest) / durations))
        assert course_bound.point_feature(c.times, np.asarray(c.tip), c.nails, c.path.launch,
                                          rest) == point  # fmt: skip
        goals = family._orientation_goals(c)
        steps, durations = course_bound._orientation_courses(c.path.start, goals, c.times,
                                                             (rest, rest), 60)  # fmt: skip
        steps, durations = np.array(steps), np.array(durations)
        w = steps / durations[:, None]
        speeds = np.linalg.norm(w, axis=1)
        incoming = np.concatenate(([0.0], speeds[:-1]))
        spin = course_bound.spin_feature(c.path.start, goals, c.times, (rest, rest), 60)
        if np.any(incoming[speeds > 1e-9] > course_bound.PACE_JUMP * speeds[speeds > 1e-9]):
            assert spin is None
            continue
        padded = np.concatenate(([0.0], speeds, [0.0]))
        fastest = np.maximum(np.maximum(padded[:-2], padded[1:-1]), padded[2:])
        change = _numpy_changes(w, rest, rest) / durations
        assert spin == float(np.max(change + course_bound.SPIN_RATE * fastest**2))
        checked += 1
    assert checked >= 2
