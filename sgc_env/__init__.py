"""sgc_env: Gymnasium environments for sequential-goal constraints (Liu, Ko & Chang 1993).

Importing the package registers the ids in :data:`ENV_IDS` with Gymnasium, each with the
``max_episode_steps`` of its episodes (:mod:`sgc_env.episode_steps`).
"""

from __future__ import annotations

import gymnasium as gym

from sgc_env.episode_steps import registered_steps
from sgc_env.observation import ObservationLayout
from sgc_env.scenario import Body, Goal, Prop, Scenario, ScenarioError, load_scenario

__all__ = [
    "ENV_IDS",
    "LEARNER_IDS",
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
_REGISTRY: dict[str, tuple[str, dict]] = {
    "SGCPoint-v0": (_ENTRY, {"random_scenario": "point"}),
    "SGCRod-v0": (_ENTRY, {"random_scenario": "rod"}),
    "SGCThreeRods-v1": (_ENTRY, {"scenario": "three_rods"}),
    "SGCIntercept-v0": (_ENTRY, {"scenario": "intercept"}),
    "SGCInterceptRandom-v0": (_ENTRY, {"random_scenario": "intercept"}),
    "SGCThreeRodsRandom-v2": (_ENTRY, {"random_scenario": "three_rods"}),
    "SGCPointGoal-v0": (f"{_GOAL}:SGCGoalEnv", {"random_scenario": "point"}),
}
ENV_IDS: tuple[str, ...] = tuple(_REGISTRY)
"""The ids on the planner's view and the ``schedule`` reward: the benchmark's leaderboards,
the shipped models and the scorecard use these versions."""

_LEARNER = {"observation": "learner", "reward": "tracking"}
_NEXT_VERSION = {
    "SGCPoint-v0": "SGCPoint-v1", "SGCRod-v0": "SGCRod-v1", "SGCThreeRods-v1": "SGCThreeRods-v2",
    "SGCIntercept-v0": "SGCIntercept-v1", "SGCInterceptRandom-v0": "SGCInterceptRandom-v1",
    "SGCThreeRodsRandom-v2": "SGCThreeRodsRandom-v3", "SGCPointGoal-v0": "SGCPointGoal-v1",
}  # fmt: skip
LEARNER_IDS: tuple[str, ...] = tuple(_NEXT_VERSION.values())
"""The newest version of every id: the same scenes and dynamics with the learner's view
(``observation="learner"``, :mod:`sgc_env.envs.learner_view`) and, but for the goal id (whose
reward is its sparse goal reward), the ``tracking`` reward (:mod:`sgc_env.envs.rewards`)."""
for _old, _new in _NEXT_VERSION.items():
    _entry, _kwargs = _REGISTRY[_old]
    _extra = {"observation": "learner"} if _entry.startswith(_GOAL) else _LEARNER
    _REGISTRY[_new] = (_entry, {**_kwargs, **_extra})

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
    """``env_id`` when Gymnasium has it registered; else a ValueError naming ``field`` and the
    SGC ids (the one check of the package, the harness, training and the CLI)."""
    if not isinstance(env_id, str) or env_id not in gym.registry:
        known = list(ENV_IDS + LEARNER_IDS)
        raise ValueError(f"{field}: unknown environment {env_id!r}; SGC ids: {known}")
    return env_id
