"""Rotation-vector deviations, Jacobians and unwrapping (sgc_env.paper.orientation)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from sgc_env.paper.orientation import (
    angular_acceleration,
    angular_velocity,
    left_jacobian,
    left_jacobian_inverse,
    left_jacobian_inverse_apply,
    orientation_deviation,
    quat_to_rotvec,
    rotvec_to_quat,
)
from sgc_env.paper.quaternion import unwrap_rotvec

vec = st.lists(st.floats(-1, 1), min_size=3, max_size=3).map(np.array)
scales = st.sampled_from([1e-6, 1e-2, 0.04, 0.06, 0.5, 2.0, 3.0, 4.0, 9.0])


def _rot(phi):
    return Rotation.from_rotvec(phi).as_matrix()


def _omega_fd(phi, phi_dot, h=1e-6):
    """World angular velocity of R(t) = Exp(phi + t phi_dot) by central differences."""
    r_p, r_m = _rot(phi + h * phi_dot), _rot(phi - h * phi_dot)
    w = Rotation.from_matrix(r_p @ r_m.T).as_rotvec() / (2 * h)
    return w


@settings(max_examples=150, deadline=None)
@given(vec, vec, scales)
def test_left_jacobian_matches_finite_differences(phi, phi_dot, scale):
    phi = phi * scale
    assert angular_velocity(phi, phi_dot) == pytest.approx(_omega_fd(phi, phi_dot), abs=1e-7)


@settings(max_examples=150, deadline=None)
@given(vec, vec, vec, scales)
def test_angular_acceleration_matches_finite_differences(phi, phi_dot, phi_ddot, scale):
    phi = phi * scale
    h = 1e-5

    def omega(t):
        p = phi + t * phi_dot + 0.5 * t * t * phi_ddot
        return angular_velocity(p, phi_dot + t * phi_ddot)

    fd = (omega(h) - omega(-h)) / (2 * h)
    assert angular_acceleration(phi, phi_dot, phi_ddot) == pytest.approx(fd, abs=1e-6)


@settings(max_examples=100, deadline=None)
@given(vec, scales)
def test_inverse_jacobian(phi, scale):
    phi = phi * scale
    if abs(np.linalg.norm(phi) - 2 * math.pi) < 1e-3:
        return
    np.testing.assert_allclose(left_jacobian_inverse(phi) @ left_jacobian(phi), np.eye(3),
                               atol=1e-9)


def test_inverse_jacobian_singular_at_two_pi():
    with pytest.raises(ValueError, match="singular"):
        left_jacobian_inverse([0.0, 0.0, 2 * math.pi])


def test_quaternion_roundtrip_and_convention():
    phi = np.array([0.3, -0.2, 0.9])
    np.testing.assert_allclose(quat_to_rotvec(rotvec_to_quat(phi)), phi, atol=1e-12)
    q = rotvec_to_quat([0, 0, math.pi / 2])
    np.testing.assert_allclose(q, [0, 0, math.sqrt(0.5), math.sqrt(0.5)], atol=1e-12)
    goal = Rotation.from_rotvec([0.1, 0.2, -0.3])
    current = Rotation.from_rotvec(phi) * goal  # R_current = Exp(phi) R_goal
    np.testing.assert_allclose(orientation_deviation(current, goal), phi, atol=1e-12)


def test_unwrap_tracks_a_somersault_continuously():
    axis = np.array([1.0, 2.0, -0.5])
    axis /= np.linalg.norm(axis)
    angles = np.linspace(-1.5 * 2 * math.pi, 0.0, 400)
    prev = angles[0] * axis
    for a in angles:
        principal = Rotation.from_rotvec(a * axis).as_rotvec()
        phi = unwrap_rotvec(principal, prev)
        np.testing.assert_allclose(phi, a * axis, atol=1e-9)
        prev = phi


def test_unwrap_identity_and_same_rotation():
    prev = np.array([0.0, 0.0, 2 * math.pi + 0.01])
    np.testing.assert_allclose(unwrap_rotvec(np.zeros(3), prev), [0, 0, 2 * math.pi])
    np.testing.assert_allclose(unwrap_rotvec([0, 0, 0], [0, 0, 6.0]), [0, 0, 2 * math.pi])
    np.testing.assert_allclose(unwrap_rotvec([0, 0, -3.0], [0, 0, 3.0]), [0, 0, 2 * math.pi - 3])
    assert unwrap_rotvec([0, 0, 0], [0, 0, 3.0]) == (0, 0, 0)
    phi = unwrap_rotvec(np.array([0.0, 0.0, 0.5]), np.array([0.0, 0.0, -5.0]))
    np.testing.assert_allclose(phi, [0, 0, 0.5 - 2 * math.pi])
    assert Rotation.from_rotvec(phi).approx_equal(Rotation.from_rotvec([0, 0, 0.5]))


@pytest.mark.parametrize("scale", [0.0, 1e-6, 0.04, 0.06, 2.0, 9.0])
def test_left_jacobian_inverse_apply_matches_the_matrix(scale):
    rng = np.random.default_rng(3)
    for _ in range(10):
        phi, omega = rng.normal(size=3) * scale, rng.normal(size=3)
        fast = left_jacobian_inverse_apply(tuple(phi), tuple(omega))
        assert np.allclose(fast, left_jacobian_inverse(phi) @ omega, rtol=1e-12, atol=1e-14)
        assert np.allclose(left_jacobian(phi) @ np.array(fast), omega, atol=1e-12)


def test_left_jacobian_inverse_apply_is_least_squares_where_singular():
    phi = np.array([2.0 * math.pi, 0.0, 0.0])
    omega = np.array([0.3, 0.0, 0.0])  # along the axis: representable
    assert np.allclose(left_jacobian_inverse_apply(phi, omega), omega, atol=1e-12)
