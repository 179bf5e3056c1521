"""Scenes: the paper's fixed three-rod builder and the random scene families.

Every family is a :class:`SceneFamily` (``draw``, ``goal_counts``, ``max_steps``); ``PRESETS``
names the ones the registered ids use. Modules: ``family`` (the protocol), ``three_rods`` (the
paper's scene), ``courses`` (one body on a random course), ``intercept`` and
``three_rods_random`` (random versions of the fixed scenes), ``course_bound`` (the planner-free
demand bound the three-rod draws check).
"""

from __future__ import annotations

import numpy as np

from sgc_env.scenario import Scenario
from sgc_env.scenes.courses import RandomScenarioConfig
from sgc_env.scenes.family import SceneFamily
from sgc_env.scenes.intercept import RandomInterceptConfig
from sgc_env.scenes.three_rods_random import RandomThreeRodsConfig

__all__ = [
    "PRESETS",
    "RandomInterceptConfig",
    "RandomScenarioConfig",
    "RandomThreeRodsConfig",
    "SceneFamily",
    "family",
    "random_scenario",
]

PRESETS: dict[str, SceneFamily] = {
    "point": RandomScenarioConfig(),
    "rod": RandomScenarioConfig(shape="rod", size=(0.6, 0.03), orientation=True),
    "intercept": RandomInterceptConfig(),
    "three_rods": RandomThreeRodsConfig(),
}


def family(config: SceneFamily | str) -> SceneFamily:
    """The family named ``config`` in ``PRESETS``, or ``config`` itself."""
    if isinstance(config, str):
        if config not in PRESETS:
            raise ValueError(
                f"random_scenario: unknown preset {config!r}; presets: {sorted(PRESETS)}"
            )
        return PRESETS[config]
    return config


def random_scenario(rng: np.random.Generator, config: SceneFamily | str = "point") -> Scenario:
    """Draw one resolved, feasible scenario of a preset or family from ``rng``."""
    return family(config).draw(rng)
