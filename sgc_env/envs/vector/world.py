"""One PyBullet client shared by the sub-envs of a batched env, their bodies kept apart.

Every sub-env builds its bodies through its own :class:`WorldView` (a
:class:`~sgc_env.simulator.Simulator` on the shared client that knows only its own bodies);
the batched env steps the whole world once per substep. Bodies of different sub-envs occupy
the same coordinates, so no object gets a collision shape (its inertia is the one PyBullet
computes for the shape): the broadphase never sees them, and bodies that cannot touch anything
integrate bit for bit as in separate clients. With collision shapes and empty masks instead,
every pair of overlapping objects still cost a broadphase test each substep: a 256-scene
three-rod world ran at 144 env-steps/s.

What the world cannot share is refused: a scene with two or more colliding objects (contacts
inside one sub-env were measured to differ from a single client's once the world holds ~32
such scenes: Bullet orders an island's contacts by the whole world's pair list; no registered
id has such a scene), a scenario whose gravity differs from the world's (PyBullet has one
gravity per client), a different simulation frequency, and snapshots of a single sub-env
(``saveState`` copies the whole world).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace
from typing import Any

from sgc_env.scenario import Scenario
from sgc_env.simulator import BodyHandle, Simulator, pybullet

__all__ = ["PropWorld", "SharedWorld", "WorldView"]


class PropWorld:
    """The client where the sub-envs' kinematic props live, made when the first prop arrives
    and never stepped. Why: props collide with nothing in a shared world (no object has a
    collision shape), so only their positions matter, and static objects in a stepped world
    cost as much per substep as bodies (three-rod worlds of 9 rods and 12 props stepped in
    15 us, 5.5 us without the props: scripts/bench_world_step.py's method)."""

    def __init__(self, sim_frequency: int) -> None:
        self._frequency = sim_frequency
        self._sim: Simulator | None = None

    @property
    def sim(self) -> Simulator:
        if self._sim is None:
            self._sim = Simulator(sim_frequency=self._frequency)
        return self._sim

    @property
    def open(self) -> bool:
        return self._sim is not None and self._sim.client >= 0

    def close(self) -> None:
        if self._sim is not None:
            self._sim.close()


class SharedWorld:
    """The shared client and what every sub-env must agree on (see the module docstring)."""

    def __init__(self, sim_frequency: int, props: PropWorld | None = None) -> None:
        self.sim = Simulator(sim_frequency=sim_frequency)
        self._own_props = props is None
        self.props = PropWorld(sim_frequency) if props is None else props
        self.gravity: tuple[float, ...] | None = None

    @property
    def client(self) -> int:
        return self.sim.client

    def view(self) -> WorldView:
        """A simulator for one more sub-env."""
        return WorldView(self)

    def check_frequency(self, sim_frequency: int) -> None:
        if sim_frequency != self.sim.sim_frequency:
            raise ValueError(
                f"sim_frequency {sim_frequency} Hz differs from the batched world's "
                f"{self.sim.sim_frequency} Hz"
            )

    def check_scenario(self, s: Scenario) -> None:
        """Refuse a scene the world cannot hold bit for bit; the first gravity becomes the
        world's (one gravity per PyBullet client)."""
        colliding = [b.name for b in s.bodies if b.collisions]
        colliding += [p.name for p in s.props if p.collisions]
        if len(colliding) >= 2:  # one colliding object alone never touches anything
            raise ValueError(
                f"scenario {s.name!r}: objects {colliding} collide with each other; contacts "
                "inside one sub-env of a shared world are not bit-identical to a single env's "
                "(see sgc_env/envs/vector/world.py), so the batched env takes scenes with at most "
                "one colliding object: set collisions: false or use single envs"
            )
        g = tuple(float(x) for x in s.gravity)
        if self.gravity is None:
            self.gravity = g
            self.sim.set_gravity(g)
        elif g != self.gravity:
            raise ValueError(
                f"scenario gravity {g} differs from the batched world's {self.gravity}: the "
                "sub-envs share one PyBullet client, which has one gravity"
            )

    def close(self) -> None:
        self.sim.close()
        if self._own_props:
            self.props.close()


class WorldView(Simulator):
    """A sub-env's simulator: the shared client, only its own bodies (see the module)."""

    def __init__(self, world: SharedWorld) -> None:  # no client of its own
        self.world = world
        self.gui = False
        self.sim_frequency = world.sim.sim_frequency
        self.client = world.client
        self.bodies: dict[str, BodyHandle] = {}
        self.markers: list[int] = []
        self._props: dict[str, int] = {}
        self._get_pose = world.sim._get_pose
        self._get_velocity = world.sim._get_velocity

    def add_body(self, name: str, *args: Any, **kwargs: Any) -> BodyHandle:
        if kwargs.get("kinematic"):
            return self._add_prop(name, *args, **kwargs)
        return self._add_dynamic(name, *args, **kwargs)

    def _add_prop(
        self, name: str, shape: str, size: Sequence[float], mass: float, *args: Any, **kwargs: Any
    ) -> BodyHandle:
        """A kinematic prop in the world's prop client (:attr:`SharedWorld.props`): a bare
        body, no collision or visual shape (moving one of hundreds of overlapping collision
        shapes updated the broadphase's pairs: 256 props took ~50 us each to place)."""
        if name in self.bodies:
            raise ValueError(f"a body named {name!r} already exists")
        sim = self.world.props.sim
        uid = pybullet.createMultiBody(baseMass=0.0, physicsClientId=sim.client)
        self.bodies[name] = handle = BodyHandle(name, uid, shape, tuple(size), float(mass))
        self._props[name] = uid
        return handle

    def remove_body(self, name: str) -> None:
        if name in self._props:
            uid = self._props.pop(name)
            self.bodies.pop(name)
            if self.world.props.open:
                pybullet.removeBody(uid, physicsClientId=self.world.props.sim.client)
            return
        super().remove_body(name)

    def move(
        self, uid: int, position: Sequence[float], orientation: Sequence[float] = (0, 0, 0, 1)
    ) -> None:
        """Place a prop (props live in the prop client)."""
        self.world.props.sim.move(uid, position, orientation)

    @property
    def prop_client(self) -> int:
        return self.world.props.sim.client

    def _add_dynamic(self, name: str, *args: Any, **kwargs: Any) -> BodyHandle:
        """A body without a collision shape, so the broadphase never sees it (N scenes at the
        same coordinates would make every pair of their objects overlap, O(N^2) per substep),
        with the mass and inertia PyBullet computes for the shape (read off a probe body made
        by :meth:`Simulator.add_body`); no visual shape either (the batched env never renders).
        """
        pb, c = pybullet, self.client
        probe = super().add_body(name, *args, **kwargs)
        mass, _, inertia = pb.getDynamicsInfo(probe.uid, -1, physicsClientId=c)[:3]
        super().remove_body(name)
        uid = pb.createMultiBody(baseMass=mass, physicsClientId=c)
        pb.changeDynamics(
            uid, -1, linearDamping=0.0, angularDamping=0.0, localInertiaDiagonal=inertia,
            physicsClientId=c,
        )  # fmt: skip
        self.bodies[name] = handle = replace(probe, uid=uid)
        return handle

    def set_gravity(self, gravity: Sequence[float]) -> None:
        """The world's gravity, set by :meth:`SharedWorld.check_scenario` (checked equal)."""

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
