"""Thin PyBullet wrapper: one physics client per instance, bodies addressed by name.

Every PyBullet call of the environment package goes through here (the env, its task and the
rendering helpers never import pybullet). Facts this module relies on (PyBullet 3.2.7, see
docs/core.md): createMultiBody bodies get damping 0.04 by default, so it is switched off;
external forces last a single simulation step, so they are re-applied on every substep; Python
API calls dominate the cost, so the hot path (:meth:`Simulator.step_bodies`,
:meth:`Simulator.body_states`) uses cached ids and bound calls.
"""

from __future__ import annotations

import contextlib
import os
import sys
import tempfile
import weakref
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

__all__ = ["BodyHandle", "BodyReading", "Drive", "Simulator", "connected_clients", "pybullet"]

BodyReading = tuple[tuple[float, ...], tuple[float, ...], tuple[float, ...], tuple[float, ...]]
"""One body as read back: position, quaternion xyzw, linear and angular velocity (world)."""

Drive = tuple[int, Sequence[float], Sequence[float] | None, Sequence[Sequence[float]]]
"""One body's control period: (uid, force, torque or None, CoM before each substep)."""


@contextlib.contextmanager
def _silenced_stderr() -> Iterator[None]:
    """Redirect the C-level stderr (fd 2): pybullet's import banner bypasses sys.stderr."""
    try:
        fd = sys.stderr.fileno()
    except (AttributeError, OSError, ValueError):
        yield
        return
    sys.stderr.flush()
    saved = os.dup(fd)
    try:
        with open(os.devnull, "w") as null:
            os.dup2(null.fileno(), fd)
            yield
    finally:
        os.dup2(saved, fd)
        os.close(saved)


def _import_pybullet() -> Any:
    if "pybullet" in sys.modules:
        return sys.modules["pybullet"]
    with _silenced_stderr():
        import pybullet as pb
    return pb


pybullet = _import_pybullet()


@dataclass(frozen=True)
class BodyHandle:
    """A created body: its PyBullet id and the shape data it was made from."""

    name: str
    uid: int
    shape: str
    size: tuple[float, ...]
    mass: float


MAX_CLIENTS = 1024  # PyBullet's limit on physics clients per process (ids are reused)


def _disconnect(client: int) -> None:
    with contextlib.suppress(Exception):
        pybullet.disconnect(physicsClientId=client)


def connected_clients() -> list[int]:
    """Ids of the PyBullet clients this process has connected (for leak checks)."""
    info = pybullet.getConnectionInfo
    return [c for c in range(MAX_CLIENTS) if info(physicsClientId=c)["isConnected"]]


class Simulator:
    """A PyBullet client (DIRECT, or GUI for ``render_mode='human'``) holding named bodies.

    The client is disconnected by :meth:`close` or, failing that, when the simulator is
    garbage-collected.
    """

    def __init__(self, *, gui: bool = False, sim_frequency: int = 240) -> None:
        pb = pybullet
        self.gui = gui
        self.sim_frequency = int(sim_frequency)
        if gui and sys.platform.startswith("linux") and not os.environ.get("DISPLAY"):
            raise RuntimeError(
                "render_mode='human' needs a display (DISPLAY is not set); use 'rgb_array'"
            )
        self.client = pb.connect(pb.GUI if gui else pb.DIRECT)
        if self.client < 0:
            raise RuntimeError("could not connect to PyBullet (is another GUI client open?)")
        # Frees the client when the simulator is garbage-collected unclosed (each one holds
        # ~30 MB); close() runs the same finaliser at once.
        self._finalizer = weakref.finalize(self, _disconnect, self.client)
        pb.setTimeStep(1.0 / self.sim_frequency, physicsClientId=self.client)
        if gui:
            pb.configureDebugVisualizer(pb.COV_ENABLE_GUI, 0, physicsClientId=self.client)
        self.bodies: dict[str, BodyHandle] = {}
        self.markers: list[int] = []
        self._get_pose = pb.getBasePositionAndOrientation
        self._get_velocity = pb.getBaseVelocity

    # ---------------------------------------------------------------- scene building

    def set_gravity(self, gravity: Sequence[float]) -> None:
        pybullet.setGravity(*map(float, gravity), physicsClientId=self.client)

    def _shapes(
        self, shape: str, size: Sequence[float], color: Sequence[float], collide: bool
    ) -> tuple[int, int]:
        pb, c = pybullet, self.client
        if shape == "sphere":
            geom: dict[str, Any] = {"shapeType": pb.GEOM_SPHERE, "radius": size[0]}
            vis = dict(geom)
        elif shape == "rod":
            geom = {"shapeType": pb.GEOM_CYLINDER, "radius": size[1], "height": size[0]}
            vis = {"shapeType": pb.GEOM_CYLINDER, "radius": size[1], "length": size[0]}
        elif shape == "box":
            geom = {"shapeType": pb.GEOM_BOX, "halfExtents": list(size)}
            vis = dict(geom)
        else:
            raise ValueError(f"unknown shape {shape!r}")
        col = pb.createCollisionShape(physicsClientId=c, **geom) if collide else -1
        visual = pb.createVisualShape(rgbaColor=list(color), physicsClientId=c, **vis)
        return col, visual

    def add_body(
        self,
        name: str,
        shape: str,
        size: Sequence[float],
        mass: float,
        color: Sequence[float],
        *,
        kinematic: bool = False,
        collisions: bool = True,
    ) -> BodyHandle:
        """Create a body once. Dynamic bodies get zero damping; kinematic ones mass 0."""
        pb, c = pybullet, self.client
        if name in self.bodies:
            raise ValueError(f"a body named {name!r} already exists")
        col, vis = self._shapes(shape, size, color, collide=True)
        uid = pb.createMultiBody(
            baseMass=0.0 if kinematic else float(mass),
            baseCollisionShapeIndex=col,
            baseVisualShapeIndex=vis,
            physicsClientId=c,
        )
        pb.changeDynamics(uid, -1, linearDamping=0.0, angularDamping=0.0, physicsClientId=c)
        if not collisions:
            pb.setCollisionFilterGroupMask(uid, -1, 0, 0, physicsClientId=c)
        handle = BodyHandle(name, uid, shape, tuple(size), float(mass))
        self.bodies[name] = handle
        return handle

    def remove_body(self, name: str) -> None:
        handle = self.bodies.pop(name)
        pybullet.removeBody(handle.uid, physicsClientId=self.client)

    def add_marker(self, radius: float, color: Sequence[float]) -> int:
        """A visual-only sphere (no collision shape, mass 0) used to show nails."""
        pb, c = pybullet, self.client
        vis = pb.createVisualShape(
            pb.GEOM_SPHERE, radius=radius, rgbaColor=list(color), physicsClientId=c
        )
        uid = pb.createMultiBody(0.0, -1, vis, [0.0, 0.0, -1e3], physicsClientId=c)
        self.markers.append(uid)
        return uid

    def move(
        self, uid: int, position: Sequence[float], orientation: Sequence[float] = (0, 0, 0, 1)
    ) -> None:
        pybullet.resetBasePositionAndOrientation(
            uid, position, orientation, physicsClientId=self.client
        )

    def inertia_diagonal(self, name: str) -> np.ndarray:
        """Principal moments of inertia (body frame) as PyBullet computed them from the shape."""
        info = pybullet.getDynamicsInfo(self.bodies[name].uid, -1, physicsClientId=self.client)
        return np.asarray(info[2], float)

    # ---------------------------------------------------------------- state

    def reset_body(
        self,
        uid: int,
        position: Sequence[float],
        orientation: Sequence[float],
        linear_velocity: Sequence[float],
        angular_velocity: Sequence[float],
    ) -> None:
        c = self.client
        pybullet.resetBasePositionAndOrientation(uid, position, orientation, physicsClientId=c)
        pybullet.resetBaseVelocity(uid, linear_velocity, angular_velocity, physicsClientId=c)

    def body_states(self, uids: Sequence[int]) -> list[BodyReading]:
        """(position, orientation, linear velocity, angular velocity) per body, one read each
        (the client positionally: PyBullet parses keywords ~0.13 us slower per call)."""
        get_pose, get_velocity = self._get_pose, self._get_velocity
        c = self.client
        return [get_pose(uid, c) + get_velocity(uid, c) for uid in uids]

    @staticmethod
    def rotation_matrix(quaternion: Sequence[float]) -> np.ndarray:
        """The 3x3 rotation matrix of a quaternion (xyzw)."""
        return np.array(pybullet.getMatrixFromQuaternion(quaternion)).reshape(3, 3)

    def step_bodies(
        self,
        drives: Sequence[Drive],
        prop_moves: Sequence[Sequence[tuple[int, Sequence[float]]]] = (),
    ) -> None:
        """Run ``len(path)`` simulation steps holding each body's force and torque.

        ``drives`` holds one ``(uid, force, torque or None, path)`` per body. The force and
        torque are re-applied on every substep because PyBullet clears them after each step.
        A WORLD_FRAME force acts at the given world point, so ``path[k]`` must be the body's
        centre of mass before substep ``k`` (anything else adds a torque); the env predicts
        it from the integrator instead of reading it back (API calls are the cost).
        ``prop_moves[k]`` lists the kinematic props to place before substep ``k``. Arguments are
        positional: PyBullet parses keywords ~0.13 us slower per call, a dozen calls a step.
        """
        pb, c = pybullet, self.client
        apply_force, apply_torque = pb.applyExternalForce, pb.applyExternalTorque
        step, reset, world = pb.stepSimulation, pb.resetBasePositionAndOrientation, pb.WORLD_FRAME
        identity = (0.0, 0.0, 0.0, 1.0)
        for k in range(len(drives[0][3])):
            if prop_moves:
                for uid, pos in prop_moves[k]:
                    reset(uid, pos, identity, c)
            for uid, force, torque, path in drives:
                apply_force(uid, -1, force, path[k], world, c)
                if torque is not None:
                    apply_torque(uid, -1, torque, world, c)
            step(c)

    def save_state(self) -> int:
        return pybullet.saveState(physicsClientId=self.client)

    def restore_state(self, state_id: int) -> None:
        pybullet.restoreState(stateId=state_id, physicsClientId=self.client)

    def state_bytes(self) -> bytes:
        """The full physics state as a .bullet file's bytes (exact, unlike re-setting poses)."""
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "state.bullet")
            pybullet.saveBullet(path, physicsClientId=self.client)
            with open(path, "rb") as fh:
                return fh.read()

    def load_state_bytes(self, data: bytes) -> None:
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "state.bullet")
            with open(path, "wb") as fh:
                fh.write(data)
            pybullet.restoreState(fileName=path, physicsClientId=self.client)

    def remove_state(self, state_id: int) -> None:
        pybullet.removeState(state_id, physicsClientId=self.client)

    # ---------------------------------------------------------------- rendering and teardown

    def orbit_image(
        self,
        width: int,
        height: int,
        target: Sequence[float],
        distance: float,
        yaw: float,
        pitch: float,
        fov: float,
    ) -> np.ndarray:
        """RGB image (H, W, 3) uint8 of an orbit camera looking at ``target`` (yaw and pitch in
        degrees); the TinyRenderer (works headless) unless this is a GUI client."""
        pb, c = pybullet, self.client
        view = pb.computeViewMatrixFromYawPitchRoll(
            list(target), distance, yaw, pitch, 0.0, 2, physicsClientId=c
        )
        projection = pb.computeProjectionMatrixFOV(
            fov, width / height, 0.01, 100.0, physicsClientId=c
        )
        renderer = pb.ER_BULLET_HARDWARE_OPENGL if self.gui else pb.ER_TINY_RENDERER
        _, _, rgba, _, _ = pb.getCameraImage(
            width, height, view, projection, renderer=renderer, physicsClientId=c
        )
        return np.asarray(rgba, dtype=np.uint8).reshape(height, width, 4)[:, :, :3].copy()

    def point_gui_camera(
        self, target: Sequence[float], distance: float, yaw: float, pitch: float
    ) -> None:
        """Aim the GUI window's camera (degrees)."""
        pybullet.resetDebugVisualizerCamera(
            distance, yaw, pitch, list(target), physicsClientId=self.client
        )

    def close(self) -> None:
        """Disconnect (idempotent); later calls on this simulator fail in PyBullet."""
        self._finalizer()
        self.client = -1
