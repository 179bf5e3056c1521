"""The size of the networks a file asks for, checked before torch builds them.

A model zip's ``policy_kwargs`` and a hyperparameter file's ``policy_kwargs`` name the
hidden layers (``net_arch``) and features-extractor widths; SB3 allocates every weight when
it builds the policy, before any loaded weight is compared, so ``net_arch: [8000, 8000, 8000,
8000]`` costs gigabytes and a minute. :func:`check_policy_kwargs` holds the widths, the depth
and the number of hidden weights to ``CAPS`` (``net_width``, ``net_layers``,
``net_parameters``) first.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from sgc_env.scenario.bounded import check_count, escaped

__all__ = ["check_net_arch", "check_policy_kwargs"]

_WIDTH_KEYS = ("features_dim", "cnn_output_dim", "n_critics")


def _widths(layers: Any, where: str) -> list[int]:
    if not isinstance(layers, list | tuple):
        raise ValueError(f"{where}: expected a list of layer widths, got {escaped(repr(layers))}")
    check_count(len(layers), "net_layers", where)
    widths = []
    for i, width in enumerate(layers):
        if isinstance(width, bool) or not isinstance(width, int) or width < 1:
            raise ValueError(f"{where}[{i}]: expected a positive integer width, got "
                             f"{escaped(repr(width))}")  # fmt: skip
        check_count(width, "net_width", f"{where}[{i}]")
        widths.append(width)
    return widths


def check_net_arch(net_arch: Any, where: str, inputs: int = 1) -> None:
    """``net_arch`` (a list, or ``{pi: [...], vf: [...]}`` / ``qf``) within the caps; the
    hidden weights counted from ``inputs`` features through every head."""
    if net_arch is None:
        return
    heads = net_arch if isinstance(net_arch, Mapping) else {"": net_arch}
    if not heads or len(heads) > 3:
        raise ValueError(f"{where}: expected a list or a mapping of pi/vf/qf lists")
    weights = 0
    for head, layers in heads.items():
        widths = _widths(layers, f"{where}.{escaped(head)}" if head else where)
        for a, b in zip([max(inputs, 1), *widths], widths, strict=False):
            weights += a * b
    check_count(weights, "net_parameters", where)


def check_policy_kwargs(kwargs: Any, where: str, inputs: int = 1) -> None:
    """The network sizes in ``policy_kwargs`` (a mapping; anything else is left to SB3)."""
    if not isinstance(kwargs, Mapping):
        return
    check_net_arch(kwargs.get("net_arch"), f"{where}.net_arch", inputs)
    extractor = kwargs.get("features_extractor_kwargs")
    sizes = {f"{where}.{k}": kwargs.get(k) for k in _WIDTH_KEYS}
    if isinstance(extractor, Mapping):
        sizes.update({f"{where}.features_extractor_kwargs.{k}": extractor.get(k)
                      for k in _WIDTH_KEYS})  # fmt: skip
    for field, value in sizes.items():
        if value is None:
            continue
        if isinstance(value, bool) or not isinstance(value, int) or value < 1:
            raise ValueError(f"{field}: expected a positive integer, got {escaped(repr(value))}")
        check_count(value, "net_width", field)
