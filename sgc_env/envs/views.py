"""Observation views: what an env observes of its step record, one class per view.

A view turns the step record (:mod:`.record`: per body the planner's block of doubles, the
time, points, forces and torques), an (N, record) float64 array, into the (N, size) float32
observations of N sub-envs at once, and one env's record (record,) into its observation; the
batched env hands the array out as it is. Both envs run the same
:meth:`ObservationView.observe`. ``SGCEnv(..., observation=...)`` picks a view by name
(:data:`VIEWS`) or takes an instance; a new view is one subclass registered with
:func:`observation_view`.
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np

from sgc_env.observation import ObservationLayout

from .choices import choose

__all__ = ["OBS_BOUND", "VIEWS", "ObservationView", "PlannerView", "make_view", "observation_view"]

OBS_BOUND = 1e5
_NO_CONSTANTS = np.zeros(0)


class ObservationView:
    """One observation of a scene (module docstring); :meth:`bind` gives it the scene's layout
    (body count and names) before the first :meth:`observe`."""

    name = "custom"

    def __init__(self) -> None:
        self.layout = ObservationLayout(1)

    def bind(self, layout: ObservationLayout) -> ObservationView:
        """A copy of this view for a scene with ``layout``."""
        view = object.__new__(type(self))
        view.__dict__.update(self.__dict__)
        view.layout = layout
        return view

    def space(self) -> gym.spaces.Box:
        """The observation space of one sub-env."""
        raise NotImplementedError

    def constants(self, env: Any) -> np.ndarray:
        """What the view needs of a sub-env besides its step record, fixed for an episode (the
        env calls it when a scene is committed; the batched env stacks the rows): none here."""
        return _NO_CONSTANTS

    def observe(self, record: np.ndarray, constants: np.ndarray | None = None) -> np.ndarray:
        """The observations (N, size) float32 of N sub-envs' step records (N, record) and their
        :meth:`constants` (N, k); for one env, a record (record,) gives its observation
        (size,) (index with ``...``)."""
        raise NotImplementedError


VIEWS: dict[str, type[ObservationView]] = {}


def observation_view(cls: type[ObservationView]) -> type[ObservationView]:
    """Register a view under its ``name`` (the ``observation=`` string that picks it)."""
    VIEWS[cls.name] = cls
    return cls


@observation_view
class PlannerView(ObservationView):
    """The planner's observation: the record's first ``layout.size`` doubles as float32 (per
    body state, goal data, deviations with their float32 residuals; then the time), laid out
    by :class:`~sgc_env.observation.ObservationLayout`, bounds +-1e5."""

    name = "planner"

    def space(self) -> gym.spaces.Box:
        return gym.spaces.Box(-OBS_BOUND, OBS_BOUND, (self.layout.size,), np.float32)

    def observe(self, record: np.ndarray, constants: np.ndarray | None = None) -> np.ndarray:
        return record[..., : self._size].astype(np.float32)

    _size = 0

    def bind(self, layout: ObservationLayout) -> ObservationView:
        view = super().bind(layout)
        view._size = layout.size  # type: ignore[attr-defined]  # a property that sums: cached
        return view


def make_view(view: object) -> ObservationView:
    """The view ``view`` names (one of :data:`VIEWS`), or ``view`` itself when it is one."""
    return choose("observation", "view", view, VIEWS, ObservationView)
