"""The benchmark's shared defaults, each written once: success tolerances and held-out seeds.

Every layer that offers one of these as a default (the metrics' ``Tolerances``, the
goal-conditioned env, the harness, training and the ``sgc`` command) reads it from here, so
changing a default is one edit.
"""

from __future__ import annotations

__all__ = ["EVAL_SEED", "ORIENTATION_TOLERANCE", "POSITION_TOLERANCE"]

POSITION_TOLERANCE = 0.02
"""A position goal is met within this distance (m) of its nail."""

ORIENTATION_TOLERANCE = 0.05
"""An orientation goal is met within this angle (rad) of its orientation."""

EVAL_SEED = 10_000
"""First held-out evaluation seed: episode k is reset with ``EVAL_SEED + k``; training,
demonstrations and DAgger use seeds below it (from the run seed on)."""
