"""Policies for the SGC environments: the analytic expert and the comparison baselines.

Built on :mod:`sgc_env` (the arrows run one way: nothing in ``sgc_env`` imports ``baselines``).
Its folders are its layers, bottom up: ``common`` (what they share of the env, files and
values), ``controllers``, ``models`` (what a model file may hold), :mod:`baselines.policies`
(one name per policy), ``evaluation`` (the harness), ``figures``, ``agents`` (training),
``benchmark``, ``zoo`` (the shipped models) and ``cli`` (the ``sgc`` command); docs/design.md
draws them.
"""

from baselines.controllers.comparison_policies import (
    DynamicConstraintsController,
    MinimumJerkController,
)
from baselines.controllers.expert import SGCExpert

__all__ = ["DynamicConstraintsController", "MinimumJerkController", "SGCExpert"]
