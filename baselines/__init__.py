"""Policies for the SGC environments: the analytic expert and the comparison baselines.

The exports load lazily (PEP 562): ``sgc_env`` imports ``baselines.sgc`` while it is being
imported itself, and an eager import of the policies here would close that cycle.
"""

from __future__ import annotations

import importlib
from typing import Any

__all__ = ["DynamicConstraintsController", "MinimumJerkController", "SGCExpert"]

_HOMES = {
    "DynamicConstraintsController": "baselines.comparison_policies",
    "MinimumJerkController": "baselines.comparison_policies",
    "SGCExpert": "baselines.expert",
}


def __getattr__(name: str) -> Any:
    if name in _HOMES:
        return getattr(importlib.import_module(_HOMES[name]), name)
    raise AttributeError(f"module 'baselines' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted([*globals(), *__all__])
