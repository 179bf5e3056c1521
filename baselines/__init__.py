"""Policies for the SGC environments: the analytic expert and the comparison baselines.

Built on :mod:`sgc_env` (the arrows run one way: nothing in ``sgc_env`` imports ``baselines``).
The harness, the agents and the ``sgc`` command live in subpackages.
"""

from baselines.controllers.comparison_policies import (
    DynamicConstraintsController,
    MinimumJerkController,
)
from baselines.controllers.expert import SGCExpert

__all__ = ["DynamicConstraintsController", "MinimumJerkController", "SGCExpert"]
