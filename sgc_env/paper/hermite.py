"""Plan-level course profiles outside the SGC family: the Hermite cubic and the dwell.

Split out of :mod:`sgc_env.paper.course` (one job per module); ``course`` re-exports both.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import cast

import numpy as np

Num = float | np.ndarray
Floats3 = tuple[float, float, float]
Arrays3 = tuple[np.ndarray, np.ndarray, np.ndarray]

__all__ = ["Evaluated", "HermiteProfile", "HoldProfile", "RestQuarticProfile"]


def _like(value: np.ndarray, t: float | np.ndarray) -> float | np.ndarray:
    return float(value) if np.ndim(t) == 0 else value


class Evaluated:
    """``position``, ``velocity`` and ``acceleration`` of a profile from its ``evaluate``
    (a float for a scalar time, else an array): shared by every course profile."""

    __slots__ = ()

    def evaluate(self, t: float | np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        raise NotImplementedError

    def position(self, t: float | np.ndarray) -> float | np.ndarray:
        """``D(t)``."""
        return _like(self.evaluate(t)[0], t)

    def velocity(self, t: float | np.ndarray) -> float | np.ndarray:
        """``D'(t)``."""
        return _like(self.evaluate(t)[1], t)

    def acceleration(self, t: float | np.ndarray) -> float | np.ndarray:
        """``D''(t)``."""
        return _like(self.evaluate(t)[2], t)


@dataclass(frozen=True)
class HermiteProfile(Evaluated):
    """Cubic Hermite course from ``(d0, v0)`` to ``(0, end_velocity)`` in ``duration``.

    Used where the SGC family does not apply: arriving at rest before a dwell on a repeated
    nail (the family cannot reach ``D = 0`` and ``D' = 0`` together), and components that
    start on the goal (``d0 == 0``). Re-fitting from any state on the curve with the remaining
    time returns the same cubic, so it is time-consistent like the SGC family. Unlike SGC it
    can overshoot, e.g. when ``v0`` points at the goal faster than ``3 |d0| / T``.
    """

    d0: float
    v0: float
    duration: float
    end_velocity: float = 0.0
    branch: str = "hermite"

    def state(self, t: float) -> tuple[float, float, float]:
        """``(D, D', D'')`` at scalar ``t`` (plain floats: the expert's per-step path)."""
        return cast(Floats3, self._cubic(float(t) / self.duration))

    def evaluate(self, t: float | np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(D, D', D'')`` at ``t`` seconds from the course start."""
        return cast(Arrays3, self._cubic(np.asarray(t, dtype=float) / self.duration))

    def _cubic(self, s: Num) -> tuple[Num, Num, Num]:
        """The cubic and its derivatives at normalised time ``s`` (a float or an array)."""
        T = self.duration
        d0, m0, m1 = self.d0, self.v0 * T, self.end_velocity * T
        # Hermite basis, end value 0: h00 = 2s^3-3s^2+1, h10 = s^3-2s^2+s, h11 = s^3-s^2
        d = d0 * (2 * s**3 - 3 * s**2 + 1) + m0 * (s**3 - 2 * s**2 + s) + m1 * (s**3 - s**2)
        v = d0 * (6 * s**2 - 6 * s) + m0 * (3 * s**2 - 4 * s + 1) + m1 * (3 * s**2 - 2 * s)
        a = d0 * (12 * s - 6) + m0 * (6 * s - 4) + m1 * (6 * s - 2)
        return d, v / T, a / (T * T)


@dataclass(frozen=True)
class RestQuarticProfile(Evaluated):
    """Quartic course from ``(d0, v0)`` to rest with zero acceleration: ``D = u^3 (c0 + c1 u)``,
    ``u = T - t``.

    The ``"matched"`` end rule's arrival at rest (before a dwell, or a last goal reached at
    rest): the cubic ends with a jump of acceleration into the hold, the quartic does not.
    Five conditions fix the quartic, so re-fitting from a state on it returns it
    (time-consistent, like the cubic).
    """

    d0: float
    v0: float
    duration: float
    branch: str = "rest-quartic"

    def state(self, t: float) -> tuple[float, float, float]:
        """``(D, D', D'')`` at scalar ``t`` (plain floats: the expert's per-step path)."""
        return cast(Floats3, self._quartic(self.duration - float(t)))

    def evaluate(self, t: float | np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(D, D', D'')`` at ``t`` seconds from the course start."""
        return cast(Arrays3, self._quartic(self.duration - np.asarray(t, dtype=float)))

    def _quartic(self, u: Num) -> tuple[Num, Num, Num]:
        T = self.duration
        c1 = -(self.v0 + 3.0 * self.d0 / T) / T**3
        c0 = (4.0 * self.d0 + self.v0 * T) / T**3
        d = u**3 * (c0 + c1 * u)
        return d, -(3.0 * c0 * u**2 + 4.0 * c1 * u**3), 6.0 * c0 * u + 12.0 * c1 * u**2


@dataclass(frozen=True)
class HoldProfile(Evaluated):
    """The dwell course ``D == 0`` (a repeated nail): the body holds the point on the nail."""

    duration: float
    branch: str = "dwell"

    def state(self, t: float) -> tuple[float, float, float]:
        return 0.0, 0.0, 0.0

    def evaluate(self, t: float | np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        zero = np.zeros_like(np.asarray(t, dtype=float))
        return zero, zero.copy(), zero.copy()
