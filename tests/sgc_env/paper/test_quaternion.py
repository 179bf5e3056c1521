"""Plain-float quaternion helpers against scipy (sgc_env.paper.quaternion)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from sgc_env.paper import quaternion as quat


@pytest.mark.parametrize("scale", [0.0, 1e-13, 1e-9, 1e-3, 1.0, 3.0, 7.0])
def test_exp_log_rotate_mul_and_matrix_match_scipy(scale):
    rng = np.random.default_rng(int(scale * 1000) + 1)
    for _ in range(20):
        r = rng.normal(size=3) * scale
        q = quat.exp(r)
        reference = Rotation.from_rotvec(r)
        assert np.allclose(Rotation.from_quat(q).as_matrix(), reference.as_matrix(), atol=1e-15)
        assert np.allclose(quat.to_matrix(q), reference.as_matrix(), atol=1e-15)
        assert np.allclose(quat.log(q), reference.as_rotvec(), atol=1e-14)
        assert abs(np.linalg.norm(quat.exp_normalized(r)) - 1.0) < 1e-15
        v = rng.normal(size=3)
        assert np.allclose(quat.rotate(q, v), reference.apply(v), atol=1e-14)
        other = Rotation.random(random_state=rng)
        product = quat.mul(q, other.as_quat())
        assert np.allclose(
            Rotation.from_quat(product).as_matrix(), (reference * other).as_matrix(), atol=1e-14
        )
        assert np.allclose(quat.mul(q, quat.conjugate(q)), (0.0, 0.0, 0.0, 1.0), atol=1e-15)
