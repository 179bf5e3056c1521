"""The failure rule: when a body ends the episode, and when its spin is clamped.

Written once for one env and for many (floats per body, or arrays over sub-envs and bodies:
:mod:`sgc_env.paper.elementwise`). A body fails outside the workspace box, at a speed of
:data:`MAX_SPEED` or more, or with a non-finite state (NaN fails every comparison); with the
workspace inside +-1e4 a body that does not fail keeps the observation inside its bounds.
PyBullet clamps |omega| at 100 rad/s: past :data:`SPIN_CLAMP` the info flags it, not terminal.
"""

from __future__ import annotations

from typing import Any

__all__ = ["MAX_SPEED", "SPIN_CLAMP", "body_flags"]

MAX_SPEED = 90.0  # m/s; PyBullet clamps linear speed at 100
SPIN_CLAMP = 99.0  # rad/s; PyBullet clamps |omega| at 100: reported, not terminal


def body_flags(state: tuple, low: tuple, high: tuple) -> tuple[Any, Any]:
    """(whether the body is fine, whether its spin is clamped) from (position, orientation,
    velocity, angular velocity) and the workspace corners."""
    pos, _, lin, ang = state
    x, y, z = pos
    vx, vy, vz = lin
    wx, wy, wz = ang
    spin = wx * wx + wy * wy + wz * wz
    ok = (
        (low[0] < x) & (x < high[0]) & (low[1] < y) & (y < high[1]) & (low[2] < z)
        & (z < high[2]) & (vx * vx + vy * vy + vz * vz < MAX_SPEED**2) & (spin == spin)
    )  # fmt: skip
    return ok, spin >= SPIN_CLAMP**2
