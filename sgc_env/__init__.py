"""sgc_env: Gymnasium environments for sequential-goal constraints (Liu, Ko & Chang 1993).

Importing the package registers the ids in :data:`ENV_IDS` with Gymnasium, each with the
``max_episode_steps`` of its episodes (:mod:`sgc_env.episode_steps`).
"""

from __future__ import annotations

import warnings

import gymnasium as gym

from sgc_env.episode_steps import registered_steps
from sgc_env.observation import ObservationLayout
from sgc_env.scenario import Body, Goal, Prop, Scenario, ScenarioError, load_scenario

__all__ = [
    "ENV_IDS",
    "check_env_id",
    "Body",
    "Goal",
    "ObservationLayout",
    "Prop",
    "Scenario",
    "ScenarioError",
    "load_scenario",
]

_ENTRY = "sgc_env.envs.sgc_env:SGCEnv"
_GOAL = "sgc_env.envs.goal_env"
_LEARNER = {"observation": "learner", "reward": "tracking"}
_REGISTRY: dict[str, tuple[str, dict]] = {
    "SGCPoint-v1": (_ENTRY, {"random_scenario": "point", **_LEARNER}),
    "SGCRod-v1": (_ENTRY, {"random_scenario": "rod", **_LEARNER}),
    "SGCThreeRods-v2": (_ENTRY, {"scenario": "three_rods", **_LEARNER}),
    "SGCIntercept-v1": (_ENTRY, {"scenario": "intercept", **_LEARNER}),
    "SGCInterceptRandom-v1": (_ENTRY, {"random_scenario": "intercept", **_LEARNER}),
    "SGCThreeRodsRandom-v3": (_ENTRY, {"random_scenario": "three_rods", **_LEARNER}),
    "SGCPointGoal-v1": (f"{_GOAL}:SGCGoalEnv", {"random_scenario": "point",
                                                "observation": "learner"}),
}  # fmt: skip
ENV_IDS: tuple[str, ...] = tuple(_REGISTRY)
"""One id per task, each at its one current version: the learner's view
(:mod:`sgc_env.envs.learner_view`) and, but for the goal id (whose reward is its sparse goal
reward), the ``tracking`` reward (:mod:`sgc_env.envs.rewards`). An earlier version of an id
(``SGCPoint-v1``, say) is not registered: ``gym.make`` answers it with Gymnasium's own
``DeprecatedEnv``, naming the current one (the migration table is in CHANGELOG.md)."""

for _id, (_entry, _kwargs) in _REGISTRY.items():
    if _id not in gym.registry:
        gym.register(
            id=_id,
            entry_point=_entry,
            kwargs=_kwargs,
            max_episode_steps=registered_steps(_kwargs),
            # No additional wrappers: Gymnasium's make_vec refuses ids that have them. Every
            # env checks its episode length itself (SGCEnv.reset); the goal id's
            # compute_reward is reached as env.unwrapped.compute_reward or through
            # env.get_wrapper_attr("compute_reward") (SB3's HER does so).
            vector_entry_point=(
                "sgc_env.envs.vector.vector_env:SGCGoalVectorEnv"
                if _entry.startswith(_GOAL)
                else "sgc_env.envs.vector.vector_env:SGCVectorEnv"
            ),
        )


def check_env_id(env_id: object, field: str = "env_id") -> str:
    """``env_id`` when Gymnasium has it registered; else a ValueError naming ``field``: for an
    earlier version of an SGC id, Gymnasium's own ``DeprecatedEnv`` message (which names the
    current id), for anything else the SGC ids (the one check of the package, the harness,
    training and the CLI)."""
    if isinstance(env_id, str) and env_id in gym.registry:
        return env_id
    if isinstance(env_id, str):
        try:
            with warnings.catch_warnings():  # the error below says it; no second line before it
                warnings.simplefilter("ignore", DeprecationWarning)
                gym.spec(env_id)
        except gym.error.DeprecatedEnv as error:
            raise ValueError(f"{field}: {error}") from None
        except gym.error.Error:
            pass
    raise ValueError(f"{field}: unknown environment {env_id!r}; SGC ids: {list(ENV_IDS)}")
