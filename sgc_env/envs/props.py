"""Kinematic prop positions at simulation substeps, computed in chunks as the episode reaches
them: memory stays bounded however long the episode (a table of every substep of a 1e4 s
episode took 835 MB), and the values are the ones a full table would hold, bit for bit."""

from __future__ import annotations

import numpy as np

from sgc_env.scenario import Prop

__all__ = ["PropPaths"]

CHUNK = 1024  # substeps per computed chunk
FIRST_CHUNK = 16
"""Substeps of the chunk a reset computes: a reset needs substep 0 only, and a full chunk of
the three-rod scene's four props cost ~1 ms of its reset (the steps compute the rest)."""


class PropPaths:
    """Positions of ``props`` at substep ``j`` (time ``j / sim_frequency``), held at the last
    substep ``last`` (props hold still if the env is stepped past truncation)."""

    def __init__(self, props: tuple[Prop, ...], sim_frequency: int, last: int) -> None:
        self._props = props
        self._frequency = sim_frequency
        self.last = last
        self._start = -1
        self._chunk = np.zeros((0, len(props), 3))

    def at(self, j: int) -> list[list[float]]:
        """One ``[x, y, z]`` per prop at substep ``min(j, last)``."""
        j = min(j, self.last)
        if not self._start <= j < self._start + len(self._chunk):
            self._fill(j, FIRST_CHUNK if j == 0 else CHUNK)
        return self._chunk[j - self._start].tolist()

    def _fill(self, start: int, size: int) -> None:
        t = np.arange(start, min(start + size, self.last + 1)) / self._frequency
        table = []
        for p in self._props:
            if p.waypoints:
                times = [w[0] for w in p.waypoints]
                pts = np.asarray([w[1] for w in p.waypoints])
                xyz = np.stack([np.interp(t, times, pts[:, k]) for k in range(3)], axis=1)
            else:
                xyz = np.asarray(p.position) + np.outer(t, p.velocity)
            table.append(xyz)
        # An array, one tolist() per read: a chunk of Python tuples (four props: 4096) kept the
        # garbage collector busy, ~20 ms a chunk in a process holding 64 scenes' chunks.
        self._chunk = np.stack(table, axis=1)
        self._start = start
