"""Files shipped inside the package (models, hyperparameters), found through importlib.resources.

They resolve the same way in a checkout and in an installed wheel, so ``sgc`` works from any
directory. A shipped model is named in a policy spec as ``shipped:<env id>`` (the BC+DAgger
model of that id) or ``shipped:<file stem>`` (any model, e.g.
``shipped:ppo_caps_SGCThreeRodsRandom-v3``).
"""

from __future__ import annotations

from importlib import resources
from importlib.resources.abc import Traversable

__all__ = [
    "SHIPPED_PREFIX",
    "hyperparams_file",
    "resolve_policy_spec",
    "shipped_files",
    "shipped_models",
]

SHIPPED_PREFIX = "shipped:"


def _data(folder: str) -> Traversable:
    return resources.files("baselines") / folder


def hyperparams_file(algo: str) -> Traversable:
    """The packaged rl-zoo3-format file ``<algo>.yml``."""
    return _data("hyperparams") / f"{algo}.yml"


def shipped_files() -> dict[str, str]:
    """File stem -> file path of every packaged model."""
    return {
        item.name[: -len(".zip")]: str(item)
        for item in sorted(_data("checkpoints").iterdir(), key=lambda t: t.name)
        if item.name.endswith(".zip")
    }


def shipped_models() -> dict[str, str]:
    """Env id -> file path of each id's BC+DAgger model (``checkpoints/ppo_dagger_<id>.zip``)."""
    prefix = "ppo_dagger_"
    return {
        stem[len(prefix) :]: path
        for stem, path in shipped_files().items()
        if stem.startswith(prefix)
    }


def resolve_policy_spec(spec: str) -> str:
    """``shipped:<env id>`` or ``shipped:<file stem>`` -> the packaged model's path; any other
    spec unchanged."""
    if not spec.startswith(SHIPPED_PREFIX):
        return spec
    name = spec[len(SHIPPED_PREFIX) :]
    models = {**shipped_files(), **shipped_models()}
    if name not in models:
        raise ValueError(f"policy: no shipped model {spec!r}; shipped: {sorted(models)}")
    return models[name]
