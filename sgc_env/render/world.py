"""The render world: a PyBullet client of its own holding visual-only copies of a scene.

Why a second client: a body created in the physics client changes what ``saveState`` /
``restoreState`` and pickling see (PyBullet refuses to restore a state into a world with a
different number of bodies), so thick rod shells, bullseye rings and carried balls in the
physics client would break ``save_state`` after a first ``render()``. Here nothing touches the
physics: each frame copies the poses in (one ``resetBasePositionAndOrientation`` per body and
prop) and TinyRenderer draws this client.

Rods are drawn as shells of radius ``rod_radius`` (a physical 0.03 m rod reads as a hair at
video size); spheres and boxes at their size; a box prop named ``target`` gets the bullseye
rings of the paper's board on its -x face.
"""

from __future__ import annotations

import weakref
from collections.abc import Sequence
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from sgc_env.render.painter import Caster
from sgc_env.simulator import pybullet

if TYPE_CHECKING:
    from sgc_env.scenario import Scenario

__all__ = ["RING_THICKNESS", "RING_TURN", "RenderWorld", "Ring", "box_corners", "bullseye_rings"]

PARKED = (0.0, 0.0, -1e3)
BULLSEYE = ((1.6, (0.85, 0.1, 0.1, 1.0)), (1.1, (0.95, 0.95, 0.95, 1.0)),
            (0.6, (0.85, 0.1, 0.1, 1.0)), (0.2, (0.95, 0.85, 0.2, 1.0)))  # fmt: skip
"""Ring radii (m) and colours on the paper's 6 x 4.4 m board, outermost first."""
RING_THICKNESS = 0.01
"""Each ring is a disc this thick (m): a cylinder whose axis :data:`RING_TURN` lays along x."""
RING_TURN: tuple[float, ...] = tuple(pybullet.getQuaternionFromEuler([0.0, np.pi / 2, 0.0]))
"""A quarter turn about y (x, y, z, w): a cylinder's z axis onto the board's normal x."""


class Ring(NamedTuple):
    """One bullseye ring: its radius and colour, and its centre's x offset from the board's."""

    radius: float
    color: tuple[float, float, float, float]
    offset: float


def bullseye_rings(half: Sequence[float]) -> list[Ring]:
    """The rings on the -x face of a board of half extents ``half``, each a little further
    out than the one it covers (so the depth test draws them in order)."""
    face = -float(half[0]) - 0.005
    return [Ring(radius, color, face - 0.006 * k) for k, (radius, color) in enumerate(BULLSEYE)]


def box_corners(centre: Sequence[float], half: Sequence[float]) -> np.ndarray:
    """The 8 corners (8, 3) of an axis-aligned box."""
    signs = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float)
    return np.asarray(centre, float) + signs * np.asarray(half, float)


class RenderWorld:
    """Visual-only bodies and props of one scenario geometry in a DIRECT client."""

    def __init__(self, scenario: Scenario, rod_radius: float | None = None) -> None:
        self.client = pybullet.connect(pybullet.DIRECT)
        # an env dropped without close() still frees this client when it is collected
        self._finalizer = weakref.finalize(self, _disconnect, self.client)
        self.bodies = scenario.bodies
        self.props = scenario.props
        self.rod_radius = [
            max(float(b.size[1]), rod_radius or 0.0) if b.shape == "rod" else 0.0
            for b in scenario.bodies
        ]
        self.body_uids = [
            self._add(b.shape, b.size, b.color, r)
            for b, r in zip(scenario.bodies, self.rod_radius, strict=True)
        ]
        self.prop_uids = [self._add(p.shape, p.size, p.color, 0.0) for p in scenario.props]
        for p in scenario.props:
            if p.name == "target" and p.shape == "box":
                self._bullseye(p.position, p.size)

    def _add(self, shape: str, size: Sequence[float], color: Sequence[float],
             rod_radius: float) -> int:  # fmt: skip
        pb, c = pybullet, self.client
        if shape == "sphere":
            vis = pb.createVisualShape(pb.GEOM_SPHERE, radius=float(size[0]),
                                       rgbaColor=list(color), physicsClientId=c)  # fmt: skip
        elif shape == "rod":
            vis = pb.createVisualShape(pb.GEOM_CYLINDER, radius=rod_radius, length=float(size[0]),
                                       rgbaColor=list(color), physicsClientId=c)  # fmt: skip
        elif shape == "box":
            vis = pb.createVisualShape(pb.GEOM_BOX, halfExtents=[float(x) for x in size],
                                       rgbaColor=list(color), physicsClientId=c)  # fmt: skip
        else:
            raise ValueError(f"render: unknown shape {shape!r}")
        return int(pb.createMultiBody(0.0, -1, vis, list(PARKED), physicsClientId=c))

    def _bullseye(self, centre: Sequence[float], half: Sequence[float]) -> None:
        """Rings on the board's -x face (visual only)."""
        for ring in bullseye_rings(half):
            disc = pybullet.createVisualShape(
                pybullet.GEOM_CYLINDER, radius=ring.radius, length=RING_THICKNESS,
                rgbaColor=list(ring.color), physicsClientId=self.client,
            )  # fmt: skip
            position = [centre[0] + ring.offset, centre[1], centre[2]]
            pybullet.createMultiBody(0.0, -1, disc, position, list(RING_TURN),
                                     physicsClientId=self.client)  # fmt: skip

    def update(self, positions: Sequence[Sequence[float]],
               orientations: Sequence[Sequence[float]],
               prop_positions: Sequence[Sequence[float]] | Sequence[np.ndarray],
               ) -> list[Caster]:  # fmt: skip
        """Pose every body and prop; returns the shadow casters of the scene."""
        casters: list[Caster] = []
        c = self.client
        for b, uid, radius, position, orientation in zip(
            self.bodies, self.body_uids, self.rod_radius, positions, orientations, strict=True
        ):
            pos, orn = [float(x) for x in position], [float(x) for x in orientation]
            pybullet.resetBasePositionAndOrientation(uid, pos, orn, physicsClientId=c)
            casters.append(_caster(b.shape, b.size, np.asarray(pos), orn, radius))
        for p, uid, at in zip(self.props, self.prop_uids, prop_positions, strict=True):
            where = [float(x) for x in at]
            pybullet.resetBasePositionAndOrientation(uid, where, [0, 0, 0, 1], physicsClientId=c)
            casters.append(_caster(p.shape, p.size, np.asarray(where), (0, 0, 0, 1), 0.0))
        return casters

    def close(self) -> None:
        """Disconnect the render client (idempotent)."""
        self._finalizer()
        self.client = -1


def _disconnect(client: int) -> None:
    try:
        pybullet.disconnect(physicsClientId=client)
    except pybullet.error:
        pass


def _caster(shape: str, size: Sequence[float], centre: np.ndarray,
            orientation: Sequence[float], rod_radius: float) -> Caster:  # fmt: skip
    if shape == "rod":
        axis = np.asarray(pybullet.getMatrixFromQuaternion(orientation)).reshape(3, 3)[:, 2]
        half = axis * float(size[0]) / 2.0
        return Caster(centre - half, centre + half, rod_radius)
    if shape == "box":
        rm = np.asarray(pybullet.getMatrixFromQuaternion(orientation)).reshape(3, 3)
        local = box_corners((0.0, 0.0, 0.0), size)
        return Caster(corners=centre + local @ rm.T)
    return Caster(centre, None, float(size[0]))
