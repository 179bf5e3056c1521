"""Environment classes, one per file."""

from sgc_env.envs.goal_env import SGCGoalEnv
from sgc_env.envs.sgc_env import SavedState, SGCEnv

__all__ = ["SGCEnv", "SGCGoalEnv", "SavedState"]
