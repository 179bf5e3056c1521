"""Names of the end-velocity rules of interior goals (a constant light enough for scenarios).

``"tangent"``: the end velocity follows the path through the neighbouring nails (beyond the
paper; :mod:`sgc_env.paper.frames` documents it). ``"paper"``: the k rules of eqs. 12-14.
Scenarios validate their ``end_velocity_rule`` against this without loading the solver.
"""

from __future__ import annotations

__all__ = ["DEFAULT_END_RULE", "END_RULES"]

END_RULES: tuple[str, ...] = ("tangent", "paper")
DEFAULT_END_RULE = "tangent"
