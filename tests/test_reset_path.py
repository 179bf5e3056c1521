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
        assert isinstance(row[0], tuple)
        assert row == [_direct(p, min(j, 3 * CHUNK), 240) for p in props], j


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
