"""A hand-set PD law for PerBodyPolicy's action head (tests only): what a shared per-body net
with no hidden layer can fly without learning."""

from __future__ import annotations

import torch as th

from baselines.models.per_body import BODY_ACTIONS, REFERENCE_ACCELERATION, PerBodyPolicy


def set_pd_law(policy: PerBodyPolicy, kp: float, kd: float) -> None:
    """No hidden layer: the head reads each body's features, two tracks of equal size (the
    learner view's time fraction after them); a PD law on both tracks' error (entries 0-2)
    and rate (3-5), in acceleration units (the features' scales: 0.05 and 0.5)."""
    width = policy.mlp_extractor.width
    track = width // 2
    weight = th.zeros(BODY_ACTIONS, width)
    for k in range(2):
        for axis in range(3):
            weight[3 * k + axis, k * track + axis] = -kp * 0.05 / REFERENCE_ACCELERATION
            weight[3 * k + axis, k * track + 3 + axis] = -kd * 0.5 / REFERENCE_ACCELERATION
    with th.no_grad():
        policy.action_net.linear.weight.copy_(weight)
        policy.action_net.linear.bias.zero_()
