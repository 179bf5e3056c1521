"""Learned agents: SB3 training, expert demonstrations and behaviour cloning.

Heavy imports (torch, stable-baselines3) live in the submodules so that importing the package
stays cheap: ``baselines.agents.train``, ``.hyperparams``, ``.callbacks``, ``.demos``, ``.bc``.
"""

from __future__ import annotations

__all__: list[str] = []
