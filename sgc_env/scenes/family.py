"""The ``SceneFamily`` protocol: what the env, the registry and the ladder need of a random
scene family, so that none of them dispatches on the family's class."""

from __future__ import annotations

from dataclasses import Field
from typing import TYPE_CHECKING, Any, ClassVar, Protocol, runtime_checkable

if TYPE_CHECKING:
    import numpy as np

    from sgc_env.scenario import Scenario

__all__ = ["SceneFamily"]


@runtime_checkable
class SceneFamily(Protocol):
    """A config the env redraws a scenario from on every reset: a frozen dataclass, so that
    ``dataclasses.replace`` can change its ``control_frequency``."""

    __dataclass_fields__: ClassVar[dict[str, Field[Any]]]

    @property
    def control_frequency(self) -> int:
        """Control ticks per second of every draw."""
        ...

    def draw(self, rng: np.random.Generator) -> Scenario:
        """One resolved scenario, feasible for the expert, drawn from ``rng`` alone."""
        ...

    def goal_counts(self) -> tuple[tuple[int, int], ...]:
        """Fewest and most goals per body over every draw."""
        ...

    def max_steps(self) -> int:
        """Most control steps an episode of any draw lasts (the registry's
        ``max_episode_steps``)."""
        ...
