"""The ``"matched"`` end rule: interior end velocities solved over a whole track.

Each SGC course solves its own behaviour equation from its start position and velocity, so a
rule that picks one goal's end velocity from the two neighbouring courses (the paper's, the
tangent rule) leaves the acceleration to jump at every goal: the track is C1, not C2
(docs/smoothness.md). Here the end velocities ``V_i`` of all interior goals of one track are
chosen together so that the acceleration at the end of course ``i`` equals the acceleration
at the start of course ``i + 1``, at every goal: ``3 (m - 1)`` equations in as many unknowns,
block-tridiagonal (goal ``i``'s residual depends on ``V_{i-1}, V_i, V_{i+1}``), solved with
``scipy.optimize.least_squares`` from the tangent rule's velocities. Every course is still an
ordinary SGC course with its end velocity realised per component of ``S_i`` (exact and
punctual); only the choice of the velocity changes. A course that ends at rest before a dwell
arrives on a :class:`~sgc_env.paper.hermite.RestQuarticProfile` with zero acceleration, so
the hold after it does not jump either; such goals and dwells keep their velocity (zero) and
have no equation. A last course reached at rest keeps the cubic: nothing follows it within
the track, and the quartic's zero end acceleration costs a larger jerk in a short last course.

Orientation tracks match the world angular acceleration ``omega_dot`` (through the left
Jacobian at each course start), position tracks the tracked point's acceleration. The first
course starts from the measured state and the last ends with the track's given velocity, so
those two ends are not matched. Where the solver does not reduce the largest mismatch, the
tangent rule's velocities are kept, and so they are where the solution's planned kink (the
largest change of ``D''`` between samples a control period apart, over the track) is not below
the tangent plan's: matching at the goals can cost a larger jerk inside the courses.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import cast

import numpy as np
from numpy.typing import ArrayLike
from scipy.optimize import least_squares
from scipy.sparse import lil_matrix

from sgc_env.paper.frames import Rows, _component_profiles, _mul, _mul_t, course_end_velocity
from sgc_env.paper.orientation import angular_acceleration, left_jacobian_inverse_apply

__all__ = ["MATCH_TOLERANCE", "MatchedEnds", "matched_end_velocities"]

_IDENTITY: Rows = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))

KINK_STEP = 1.0 / 60.0
"""Sample spacing of the planned-kink check (s): the env's control period by default."""

MAX_EVALUATIONS = 20
"""Solver iterations at most: a track that does not match by then keeps its best compromise
(measured: the matching tracks of the three-rod scenes converge in 5-10)."""

MATCH_TOLERANCE = 1e-6
"""Largest acceleration mismatch at a goal (m/s² or rad/s²) for ``converged``."""


@dataclass(frozen=True)
class MatchedEnds:
    """End velocity of every course of a track (``(m, 3)``, world; the last row is the
    track's given end velocity) and how well the accelerations match (largest mismatch at a
    goal with an equation, before and after solving)."""

    velocities: np.ndarray
    free: tuple[int, ...]
    mismatch_before: float
    mismatch: float
    solved: bool = True
    """False where the tangent rule's velocities were kept (no goal to match, or solving did
    not lower the mismatch and the planned kink)."""

    @property
    def converged(self) -> bool:
        return self.mismatch <= MATCH_TOLERANCE


def _negligible(x: np.ndarray, scale: float) -> bool:
    return float(np.linalg.norm(x)) <= 1e-9 * max(scale, 1e-300)


def matched_end_velocities(
    starts: ArrayLike,
    durations: ArrayLike,
    start_velocity: ArrayLike,
    end_velocity: ArrayLike,
    *,
    orientation: bool,
) -> MatchedEnds:
    """Solve a track's interior end velocities so accelerations match at every goal.

    ``starts``: ``D_i(0)`` of every course (``(m, 3)``; for orientation ``phi_i(0)``, the
    negated sub-rotation); ``durations``: ``t_i``; ``start_velocity``: the world velocity at
    the track start (for orientation the angular velocity ``omega``); ``end_velocity``: the
    last course's end velocity (zeros: arrive at rest).
    """
    s = np.asarray(starts, float).reshape(-1, 3)
    t = np.asarray(durations, float).reshape(-1)
    end = np.asarray(end_velocity, float).reshape(3)
    m = len(t)
    if s.shape[0] != m or m == 0:
        raise ValueError(f"starts has {s.shape[0]} rows and durations {m}: one per course")
    w0 = np.asarray(start_velocity, float).reshape(3)
    frames, guess, rest = [], np.zeros((m, 3)), []
    for i in range(m):
        last = i == m - 1
        v, info = course_end_velocity(
            s[i], None if last else s[i + 1], float(t[i]), None if last else float(t[i + 1]),
            end_velocity=end if last else None, rule="tangent",
        )  # fmt: skip
        frames.append(info.frame)
        guess[i] = v
        rest.append(info.rule in ("rest", "dwell"))
    free = tuple(
        i for i in range(m - 1)
        if not rest[i] and not _negligible(s[i + 1], float(np.linalg.norm(s[i])))
    )  # fmt: skip

    def start_rate(i: int, velocity: np.ndarray) -> np.ndarray:
        if not orientation:
            return velocity
        return np.array(left_jacobian_inverse_apply(s[i], velocity))

    rows: list[Rows] = [
        _IDENTITY if f is None else cast(Rows, tuple(tuple(r) for r in f.tolist())) for f in frames
    ]
    local = [_mul(rows[i], tuple(s[i].tolist())) for i in range(m)]

    def course(i: int, ends: np.ndarray) -> tuple:
        """Course ``i``'s component profiles in ``S_i`` (plain floats: the solver's inner loop)."""
        v_in = start_rate(i, w0 if i == 0 else ends[i - 1])
        return _component_profiles(
            local[i], _mul(rows[i], tuple(v_in.tolist())), _mul(rows[i], tuple(ends[i].tolist())),
            float(t[i]), i < m - 1,
        )  # fmt: skip

    def acceleration(c: tuple, at: float, i: int) -> np.ndarray:
        s0, s1, s2 = (p.state(at) for p in c)
        a = np.array(_mul_t(rows[i], (s0[2], s1[2], s2[2])))
        if not orientation:
            return a
        d = _mul_t(rows[i], (s0[0], s1[0], s2[0]))
        return angular_acceleration(d, _mul_t(rows[i], (s0[1], s1[1], s2[1])), a)

    def residual(x: np.ndarray) -> np.ndarray:
        ends = guess.copy()
        ends[list(free)] = x.reshape(-1, 3)
        cache: dict[int, tuple] = {}
        out = []
        for i in free:
            for j in (i, i + 1):
                if j not in cache:
                    cache[j] = course(j, ends)
            jump = acceleration(cache[i], float(t[i]), i) - acceleration(cache[i + 1], 0.0, i + 1)
            out.append(jump)
        return np.concatenate(out)

    if not free:
        return MatchedEnds(guess, free, 0.0, 0.0, solved=False)
    x0 = guess[list(free)].ravel()
    before = float(np.abs(residual(x0)).max())
    n = len(free)
    pattern = lil_matrix((3 * n, 3 * n), dtype=int)
    for a in range(n):
        for b in range(max(0, a - 1), min(n, a + 2)):
            pattern[3 * a : 3 * a + 3, 3 * b : 3 * b + 3] = 1
    try:
        sol = least_squares(
            residual, x0, jac_sparsity=pattern, method="trf", xtol=1e-12, ftol=1e-12,
            gtol=1e-12, max_nfev=MAX_EVALUATIONS,
        )  # fmt: skip
    except ValueError:  # residuals not finite (e.g. the tangent start overflows a course)
        return MatchedEnds(guess, free, before, before, solved=False)
    after = float(np.abs(residual(sol.x)).max())
    out = guess.copy()
    out[list(free)] = sol.x.reshape(-1, 3)

    def planned_kink(ends: np.ndarray) -> float:
        """Largest change of the planned ``D''`` between samples ``KINK_STEP`` apart."""
        acc = []
        for i in range(m):
            c = course(i, ends)
            n = max(1, int(round(float(t[i]) / KINK_STEP)))
            for tk in np.linspace(float(t[i]) / n, float(t[i]), n):
                s0, s1, s2 = (p.state(float(tk)) for p in c)
                acc.append(_mul_t(rows[i], (s0[2], s1[2], s2[2])))
        return float(np.max(np.linalg.norm(np.diff(np.array(acc), axis=0), axis=1)))

    if not (math.isfinite(after) and after < before and planned_kink(out) < planned_kink(guess)):
        return MatchedEnds(guess, free, before, before, solved=False)
    return MatchedEnds(out, free, before, after)
