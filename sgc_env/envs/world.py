"""One PyBullet client shared by the sub-envs of a batched env, their bodies kept apart.

Every sub-env builds its bodies through its own :class:`WorldView` (a
:class:`~sgc_env.simulator.Simulator` on the shared client that knows only its own bodies);
the batched env steps the whole world once per substep. Bodies of different sub-envs occupy
the same coordinates, so collisions between them are filtered off: a sub-env whose objects
cannot touch each other (a single colliding object) gets an empty collision mask; otherwise
its colliding objects share one of :data:`CLASSES` group bits (sub-env index modulo the
number of bits) and a pair rule switches off every pair with a class-mate of another sub-env
(PyBullet's pair rules take precedence over group masks). Without contacts between them,
bodies in one world integrate bit for bit as in separate clients.

What the world cannot share is refused: a scenario whose gravity differs from the world's
(PyBullet has one gravity per client), a different simulation frequency, and snapshots of a
single sub-env (``saveState`` copies the whole world).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from sgc_env.simulator import BodyHandle, Simulator, pybullet

__all__ = ["CLASSES", "SharedWorld", "WorldView"]

CLASSES = 30
"""Collision group bits used (PyBullet's group and mask are C ints; bit 31 is the sign)."""


class SharedWorld:
    """The shared client plus the collision bookkeeping (see the module docstring)."""

    def __init__(self, sim_frequency: int) -> None:
        self.sim = Simulator(sim_frequency=sim_frequency)
        self.gravity: tuple[float, ...] | None = None
        self._owner: dict[int, int] = {}  # uid -> sub-env index (colliding objects only)
        self._members: dict[int, set[int]] = {}  # class -> colliding uids in class mode
        self._rules: dict[int, set[int]] = {}  # uid -> partners with a pair rule written
        self._views = 0

    @property
    def client(self) -> int:
        return self.sim.client

    def view(self) -> WorldView:
        """A simulator for the next sub-env (index = number of views made so far)."""
        self._views += 1
        return WorldView(self, self._views - 1)

    def check_frequency(self, sim_frequency: int) -> None:
        if sim_frequency != self.sim.sim_frequency:
            raise ValueError(
                f"sim_frequency {sim_frequency} Hz differs from the batched world's "
                f"{self.sim.sim_frequency} Hz"
            )

    def check_gravity(self, gravity: Sequence[float]) -> None:
        """Accept the first gravity; refuse any other (one gravity per PyBullet client)."""
        g = tuple(float(x) for x in gravity)
        if self.gravity is None:
            self.gravity = g
            self.sim.set_gravity(g)
        elif g != self.gravity:
            raise ValueError(
                f"scenario gravity {g} differs from the batched world's {self.gravity}: the "
                "sub-envs share one PyBullet client, which has one gravity"
            )

    def filter(self, index: int, objects: Sequence[tuple[int, bool]]) -> None:
        """Set the collision filters of a sub-env's freshly built ``(uid, collides)`` objects."""
        c, pb = self.sim.client, pybullet
        colliding = [uid for uid, collides in objects if collides]
        shared = len(colliding) >= 2  # a lone object cannot touch anything of its own env
        cls = index % CLASSES
        if shared:
            for uid in colliding:
                self._owner[uid] = index
        for uid, collides in objects:
            if collides and shared:
                bit = 1 << cls
                pb.setCollisionFilterGroupMask(uid, -1, bit, bit, physicsClientId=c)
            else:
                pb.setCollisionFilterGroupMask(uid, -1, 0, 0, physicsClientId=c)
            # Rules left from an earlier owner of this uid (PyBullet reuses ids) get the value
            # this body needs; rules override masks, so a stale one must never stay enabled.
            for partner in self._rules.get(uid, ()):
                same = self._owner.get(partner) == index and collides and shared
                self._rule(uid, partner, same)
        if not shared:
            return
        members = self._members.setdefault(cls, set())
        for uid in colliding:
            for other in members:
                if self._owner[other] != index:
                    self._rule(uid, other, False)
        members.update(colliding)

    def _rule(self, a: int, b: int, enable: bool) -> None:
        pybullet.setCollisionFilterPair(a, b, -1, -1, int(enable), physicsClientId=self.sim.client)
        self._rules.setdefault(a, set()).add(b)
        self._rules.setdefault(b, set()).add(a)

    def forget(self, uid: int) -> None:
        """A body was removed: it leaves its class (its rules are rewritten on reuse)."""
        if self._owner.pop(uid, None) is not None:
            for members in self._members.values():
                members.discard(uid)

    def close(self) -> None:
        self.sim.close()


class WorldView(Simulator):
    """A sub-env's simulator: the shared client, only its own bodies (see the module)."""

    def __init__(self, world: SharedWorld, index: int) -> None:  # no client of its own
        self.world = world
        self.index = index
        self.gui = False
        self.sim_frequency = world.sim.sim_frequency
        self.client = world.client
        self.bodies: dict[str, BodyHandle] = {}
        self.markers: list[int] = []
        self._get_pose = world.sim._get_pose
        self._get_velocity = world.sim._get_velocity

    def set_gravity(self, gravity: Sequence[float]) -> None:
        self.world.check_gravity(gravity)

    def remove_body(self, name: str) -> None:
        uid = self.bodies[name].uid
        super().remove_body(name)
        self.world.forget(uid)

    def built(self, collides: Sequence[tuple[str, bool]]) -> None:
        self.world.filter(self.index, [(self.bodies[n].uid, c) for n, c in collides])

    def step_bodies(self, *args: Any, **kwargs: Any) -> None:
        raise RuntimeError("a sub-env of a batched env is stepped by its vector env")

    def _whole_world(self, *args: Any, **kwargs: Any) -> Any:
        raise NotImplementedError(
            "a sub-env of a batched env shares its PyBullet client: snapshots (save_state, "
            "restore_state, pickling) would copy every sub-env; use single envs for them"
        )

    save_state = restore_state = state_bytes = load_state_bytes = remove_state = _whole_world

    def close(self) -> None:
        """Remove this sub-env's bodies; the world keeps its client."""
        if self.client >= 0 and self.world.client >= 0:
            for name in list(self.bodies):
                self.remove_body(name)
        self.client = -1
