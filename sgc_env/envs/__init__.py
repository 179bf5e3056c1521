"""Environment classes, one per file."""

from sgc_env.envs.goal_env import SGCGoalEnv
from sgc_env.envs.learner_view import LearnerView
from sgc_env.envs.sgc_env import SavedState, SGCEnv, StepInfo
from sgc_env.envs.task import GoalEvent, GoalTask

__all__ = ["GoalEvent", "GoalTask", "LearnerView", "SGCEnv", "SGCGoalEnv", "SavedState", "StepInfo"]
