"""Snapshots of one env's physics and goal counters (``SGCEnv.save_state``).

The PyBullet copy lives in the client; a finaliser frees it when the snapshot is freed,
garbage-collected, or its simulator closed, whichever comes first.
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass
from typing import Any

from sgc_env.simulator import Simulator

__all__ = ["SavedState"]


@dataclass(frozen=True)
class SavedState:
    """A snapshot from :meth:`SGCEnv.save_state`: the PyBullet state id plus env counters."""

    bullet_state: int
    counters: dict[str, Any]

    @classmethod
    def of(cls, sim: Simulator, counters: dict[str, Any]) -> SavedState:
        """Save ``sim``'s state now, freed with the snapshot (see the module docstring)."""
        return _attach(cls(sim.save_state(), counters), sim)

    def free(self) -> None:
        """Free the PyBullet copy now instead of when this object is garbage-collected."""
        release = getattr(self, "_release", None)
        if release is not None:
            release()

    @property
    def alive(self) -> bool:
        """False once freed (explicitly or because its env closed)."""
        release = getattr(self, "_release", None)
        if release is None:
            return True
        details = release.peek()
        return details is not None and _sim_open(details[2][0])


def _sim_open(sim_ref: weakref.ref[Simulator]) -> bool:
    sim = sim_ref()
    return sim is not None and sim.client >= 0


def _remove_state(sim_ref: weakref.ref[Simulator], state_id: int) -> None:
    if _sim_open(sim_ref):
        sim_ref().remove_state(state_id)  # type: ignore[union-attr]


def _attach(state: SavedState, sim: Simulator) -> SavedState:
    object.__setattr__(
        state,
        "_release",
        weakref.finalize(state, _remove_state, weakref.ref(sim), state.bullet_state),
    )
    return state
