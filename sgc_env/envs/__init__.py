"""Environment classes, one per file."""

from sgc_env.envs.goal_env import SGCGoalEnv
from sgc_env.envs.sgc_env import SavedState, SGCEnv, StepInfo
from sgc_env.envs.task import GoalEvent, GoalTask

__all__ = ["GoalEvent", "GoalTask", "SGCEnv", "SGCGoalEnv", "SavedState", "StepInfo"]
