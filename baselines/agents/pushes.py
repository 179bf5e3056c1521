"""Random pushes during demonstrations and DAgger rollouts, for state diversity.

On a fixed scene (``SGCIntercept-v1``, ``SGCThreeRods-v2``) every reset gives the same
scenario, so every expert demonstration is the same trajectory and a clone never sees a state
off it. A push (:meth:`SGCEnv.apply_impulse`) knocks a body off course between two ticks; the
expert re-plans from any state, so its actions after a push are the recovery a clone needs to
learn. Pushes are drawn from a generator seeded by the episode's reset seed alone, so a
rollout is reproducible and independent of the policy being rolled out.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from sgc_env.paper.quaternion import to_matrix

__all__ = ["PUSH_STREAM", "Pushes", "apply_random_push", "push_rng"]

PUSH_STREAM = 0x5055_5348
"""Second SeedSequence word, so the push stream never equals another use of the same seed."""


@dataclass(frozen=True)
class Pushes:
    """How to push; the defaults push nothing.

    ``scale`` (m/s) and ``spin`` (rad/s) are per-axis standard deviations of the linear and
    angular velocity change, ``prob`` the chance of a push at each tick, ``start`` a push at
    tick 0 of every episode (a randomised start).
    """

    scale: float = 0.0
    spin: float = 0.0
    prob: float = 0.05
    start: bool = False

    def __post_init__(self) -> None:
        for name in ("scale", "spin"):
            value = getattr(self, name)
            if not math.isfinite(value) or value < 0:
                raise ValueError(f"push_{name} must be finite and >= 0, got {value!r}")
        if not 0.0 <= self.prob <= 1.0:
            raise ValueError(f"push_prob must be in [0, 1], got {self.prob!r}")
        if self.start and not self.active:
            raise ValueError("push_start needs push_scale > 0 or push_spin > 0")

    @property
    def active(self) -> bool:
        return self.scale > 0 or self.spin > 0

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


def push_rng(episode_seed: int) -> np.random.Generator:
    """The push generator of one episode, from its reset seed only."""
    if episode_seed < 0:
        raise ValueError(f"seed: pushes need a reset seed >= 0, got {episode_seed}")
    return np.random.default_rng([int(episode_seed), PUSH_STREAM])


def _angular_impulse(base: Any, body: int, spin: np.ndarray) -> np.ndarray:
    """World-frame angular impulse that changes the body's angular velocity by ``spin``.

    ``I_world = R diag(I) R^T``: scaling by the inertia matters for a rod, whose inertia about
    its own axis is a hundred times smaller than across it. The orientation is the planner's
    state (whatever the env observes).
    """
    state = base.planner_observation()
    quat = state[base.layout.body_slice(body, "orientation")].astype(float)
    rot = np.array(to_matrix(quat / np.linalg.norm(quat)))
    return rot @ (base.body_inertia[body] * (rot.T @ spin))


def apply_random_push(
    env: Any, obs: np.ndarray, pushes: Pushes, rng: np.random.Generator, tick: int
) -> np.ndarray:
    """Maybe push one body (drawn uniformly) and return the observation the policy should see.

    Without a push, ``obs`` comes back unchanged and ``rng`` is drawn from only when
    ``pushes`` is active, so the default settings reproduce unpushed rollouts exactly.
    """
    if not pushes.active:
        return obs
    forced = pushes.start and tick == 0
    if rng.random() >= pushes.prob and not forced:
        return obs
    base = env.unwrapped
    body = int(rng.integers(len(base.scenario.bodies)))
    velocity = rng.normal(0.0, pushes.scale, 3)
    spin = rng.normal(0.0, pushes.spin, 3)
    linear = base.scenario.bodies[body].mass * velocity
    angular = _angular_impulse(base, body, spin) if base.use_torque else np.zeros(3)
    return np.array(base.apply_impulse(body, linear, angular), dtype=np.float32)
