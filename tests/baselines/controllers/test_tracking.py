"""The deadbeat tracking model must agree with PyBullet to floating point."""

from __future__ import annotations

import numpy as np
import pybullet as p
import pytest
from scipy.spatial.transform import Rotation

from baselines.controllers.tracking import (
    _linear_model,
    _linear_model_axisymmetric,
    _simulate_axisymmetric,
    held_acceleration_for_position,
    rotation_residual,
    simulate_rotation,
    torque_for_orientation,
)

H = 1.0 / 240.0
SUBSTEPS = 4
GRAVITY = np.array([0.0, 0.0, -9.81])


@pytest.fixture(scope="module")
def rod():
    client = p.connect(p.DIRECT)
    p.setGravity(*GRAVITY, physicsClientId=client)
    p.setTimeStep(H, physicsClientId=client)
    shape = p.createCollisionShape(p.GEOM_CAPSULE, radius=0.02, height=1.0, physicsClientId=client)
    body = p.createMultiBody(2.0, shape, -1, [0, 0, 1], [0, 0, 0, 1], physicsClientId=client)
    p.changeDynamics(body, -1, linearDamping=0, angularDamping=0, physicsClientId=client)
    inertia = p.getDynamicsInfo(body, -1, physicsClientId=client)[2]
    yield client, body, 2.0, inertia
    p.disconnect(client)


def _step_held(client, body, force, torque):
    for _ in range(SUBSTEPS):
        position, _ = p.getBasePositionAndOrientation(body, physicsClientId=client)
        p.applyExternalForce(body, -1, list(force), position, p.WORLD_FRAME, physicsClientId=client)
        p.applyExternalTorque(body, -1, list(torque), p.WORLD_FRAME, physicsClientId=client)
        p.stepSimulation(physicsClientId=client)
    position, orientation = p.getBasePositionAndOrientation(body, physicsClientId=client)
    velocity, angular_velocity = p.getBaseVelocity(body, physicsClientId=client)
    return np.array(position), np.array(orientation), np.array(velocity), np.array(angular_velocity)


@pytest.mark.parametrize("seed", range(12))
def test_deadbeat_lands_exactly_on_targets(rod, seed):
    client, body, mass, inertia = rod
    rng = np.random.default_rng(seed)
    q0 = Rotation.random(random_state=seed).as_quat()
    x0, v0, w0 = rng.normal(size=3), rng.normal(size=3), rng.normal(size=3) * 3
    p.resetBasePositionAndOrientation(body, x0.tolist(), q0.tolist(), physicsClientId=client)
    p.resetBaseVelocity(body, v0.tolist(), w0.tolist(), physicsClientId=client)
    period = SUBSTEPS * H
    x_target = x0 + v0 * period + rng.normal(size=3) * 1e-3
    q_target = (
        Rotation.from_rotvec(rng.normal(size=3) * 0.02)
        * Rotation.from_rotvec(w0 * period)
        * Rotation.from_quat(q0)
    ).as_quat()
    accel = held_acceleration_for_position(x0, v0, x_target, H, SUBSTEPS)
    force = mass * (accel - GRAVITY)
    torque = torque_for_orientation(q0, w0, q_target, inertia, H, SUBSTEPS)
    x, q, _, _ = _step_held(client, body, force, torque)
    assert np.max(np.abs(x - x_target)) < 1e-13
    assert (Rotation.from_quat(q) * Rotation.from_quat(q_target).inv()).magnitude() < 1e-12


def test_rotation_model_matches_pybullet(rod):
    client, body, _, inertia = rod
    q0 = Rotation.from_rotvec([0.3, -0.2, 0.9]).as_quat()
    w0 = np.array([0.5, 2.0, 7.0])
    torque = (0.01, -0.03, 0.002)
    p.resetBasePositionAndOrientation(body, [0, 0, 1], q0.tolist(), physicsClientId=client)
    p.resetBaseVelocity(body, [0, 0, 0], w0.tolist(), physicsClientId=client)
    _, q, _, w = _step_held(client, body, np.zeros(3) - 2.0 * GRAVITY, torque)
    q_model, w_model = simulate_rotation(q0, w0, torque, inertia, H, SUBSTEPS)
    assert np.max(np.abs(np.array(w_model) - w)) < 1e-12
    assert np.max(np.abs(rotation_residual(q, q_model))) < 1e-13


def test_first_guess_is_close_for_gentle_targets(rod):
    _, _, _, inertia = rod
    q0 = Rotation.from_rotvec([0.1, 0.2, 0.3]).as_quat()
    w0 = np.array([0.2, -0.1, 0.05])
    q_target = (Rotation.from_rotvec(w0 * SUBSTEPS * H + 1e-4) * Rotation.from_quat(q0)).as_quat()
    torque = torque_for_orientation(q0, w0, q_target, inertia, H, SUBSTEPS, exact=False)
    reached, _ = simulate_rotation(q0, w0, torque, inertia, H, SUBSTEPS)
    assert np.max(np.abs(rotation_residual(reached, q_target))) < 1e-6


@pytest.mark.parametrize("inertia", [(0.02, 0.02, 1e-5), (0.3, 0.3, 0.3), (1.0, 1.0, 0.5)])
def test_axisymmetric_closed_forms_match_the_matrix_forms(inertia):
    rng = np.random.default_rng(5)
    for _ in range(5):
        q = tuple(Rotation.random(random_state=rng).as_quat())
        w, tau = tuple(rng.normal(size=3) * 5), tuple(rng.normal(size=3) * 0.01)
        a_general, g_general = _linear_model(q, w, inertia, H, SUBSTEPS)
        a_fast, g_fast = _linear_model_axisymmetric(q, w, inertia, H, SUBSTEPS)
        assert np.allclose(a_fast, a_general, rtol=1e-13, atol=1e-15 * np.max(a_general))
        assert np.allclose(g_fast, g_general, rtol=1e-11, atol=1e-15)
        q_matrix, w_matrix = simulate_rotation(q, w, tau, inertia, H, SUBSTEPS)
        q_fast, w_fast = _simulate_axisymmetric(q, w, tau, inertia, H, SUBSTEPS)
        assert np.max(np.abs(rotation_residual(q_fast, q_matrix))) < 1e-14
        assert np.allclose(w_fast, w_matrix, rtol=1e-12, atol=1e-12)


def test_refine_false_returns_the_first_guess(rod):
    _, _, _, inertia = rod
    q0 = Rotation.from_rotvec([0.1, 0.2, 0.3]).as_quat()
    w0 = np.array([0.2, -0.1, 0.05])
    q_target = (Rotation.from_rotvec(w0 * SUBSTEPS * H + 1e-4) * Rotation.from_quat(q0)).as_quat()
    args = (q0, w0, q_target, inertia, H, SUBSTEPS)
    guess = torque_for_orientation(*args, exact=False, refine=False)
    corrected = torque_for_orientation(*args, exact=False)
    reached = [simulate_rotation(q0, w0, t, inertia, H, SUBSTEPS)[0] for t in (guess, corrected)]
    miss = [np.max(np.abs(rotation_residual(r, q_target))) for r in reached]
    assert miss[1] < miss[0] < 1e-6
