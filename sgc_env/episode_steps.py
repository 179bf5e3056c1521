"""How many control steps an episode lasts: the ``max_episode_steps`` each registered id declares.

The env truncates by itself at the last goal's tick plus ``scenario.margin``; the registry's
bound lets tools that read the spec (``TimeLimit``, ``TimeAwareObservation``, rl-zoo3) know
it. A built-in scenario's bound equals the env's own (both truncate on the same step); a
random-scenario id's bound covers every draw of its preset, so its TimeLimit never cuts an
episode short of the env's own truncation. The bound is for the registered arguments: a
longer scenario (``scenario=``, ``reset(options={"scenario": ...})``, a higher
``control_frequency``) would be cut short silently, so :class:`EpisodeLengthCheck` (the
outermost registered wrapper) turns that into a ``ValueError`` at reset.
"""

from __future__ import annotations

import math
from typing import Any

import gymnasium as gym

from sgc_env.scenario import Scenario, resolve_scenario, scenario_from_dict
from sgc_env.scenario.load import builtin_data
from sgc_env.scenario.model import grid_tick
from sgc_env.scenes import SceneFamily, family

__all__ = [
    "EpisodeLengthCheck",
    "check_episode_length",
    "check_registered_length",
    "random_steps_bound",
    "registered_steps",
    "scenario_steps",
]


def scenario_steps(scenario: Scenario) -> int:
    """Steps of an episode of ``scenario``: its last goal's tick plus the margin's ticks.

    The same count as ``SGCEnv.max_steps``. An unresolved scenario is resolved only when a
    body's last goal has no time of its own (routing places untimed goals before timed ones).
    """
    if any(b.goals and b.goals[-1].time is None for b in scenario.bodies):
        scenario = resolve_scenario(scenario)
    f = scenario.control_frequency
    times = [float(g.time) for b in scenario.bodies for g in b.goals if g.time is not None]
    return max(grid_tick(t, f) for t in times) + math.ceil(scenario.margin * f - 1e-9)


def random_steps_bound(config: SceneFamily | str) -> int:
    """Most steps an episode of a random-scenario preset or family can last (every draw)."""
    return family(config).max_steps()


def registered_steps(kwargs: dict[str, Any]) -> int:
    """``max_episode_steps`` for an id registered with these ``SGCEnv`` keyword arguments."""
    if kwargs.get("random_scenario") is not None:
        return random_steps_bound(kwargs["random_scenario"])
    return scenario_steps(_builtin(kwargs["scenario"]))


def _builtin(name: str) -> Scenario:
    """A built-in scenario as written (validated, not resolved: cheap enough for import)."""
    return scenario_from_dict(builtin_data(name), name=name)


def check_episode_length(
    env_id: str, limit: int | None, needed: int, remedy: str = "to gym.make or gym.make_vec"
) -> None:
    """A ValueError when the registry's own TimeLimit of ``env_id`` (``limit``, the steps an
    episode may last) would end an episode of ``needed`` steps early; a limit the caller chose
    (any other value) is left alone. ``remedy`` ends the message (where to pass a limit)."""
    if limit is None or needed <= limit or env_id not in gym.registry:
        return
    if limit == gym.spec(env_id).max_episode_steps:
        raise ValueError(
            f"{env_id}: this episode lasts {needed} steps but the registered TimeLimit ends "
            f"episodes after {limit}; pass max_episode_steps={needed} (or -1 for no TimeLimit) "
            f"{remedy}"
        )


def check_registered_length(spec: Any, needed: int) -> None:
    """For an env made by ``gym.make`` (its ``spec``) from an id without an
    :class:`EpisodeLengthCheck` wrapper (one would stop ``gym.make_vec`` from using the batched
    env): refuse an episode longer than the id's registered TimeLimit, which would cut it
    short silently. The env cannot see a TimeLimit the caller chose; longer episodes run on
    ``SGCEnv`` made directly or through ``gym.make_vec(id, ..., max_episode_steps=...)``."""
    if spec is None or spec.id not in gym.registry:
        return
    registered = gym.spec(spec.id)
    if not registered.additional_wrappers:
        check_episode_length(
            spec.id, registered.max_episode_steps, needed,
            "to gym.make_vec, or construct sgc_env.envs.SGCEnv directly (gym.make's own "
            "max_episode_steps cannot reach the env)",
        )  # fmt: skip


class EpisodeLengthCheck(gym.Wrapper, gym.utils.RecordConstructorArgs):
    """Refuses, at reset, an episode that the registered ``TimeLimit`` would end too early.

    Only the registry's own bound is checked: a ``max_episode_steps`` passed to ``gym.make``
    is the caller's choice and is left alone.
    """

    def __init__(self, env: gym.Env) -> None:
        gym.utils.RecordConstructorArgs.__init__(self)
        gym.Wrapper.__init__(self, env)

    def reset(self, **kwargs: Any) -> tuple[Any, dict[str, Any]]:
        result = self.env.reset(**kwargs)
        spec, base = self.env.spec, self.env.unwrapped
        limit = None if spec is None else spec.max_episode_steps
        if base.spec is not None:
            check_episode_length(base.spec.id, limit, int(getattr(base, "max_steps", 0)))
        return result
