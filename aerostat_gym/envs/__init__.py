"""Gymnasium environments: ``TetheredAerostat-v0`` (single and native vector) and the SB3 adapter.

One layer, one job per file: ``spaces`` (observation table and named channels), ``reward`` (the
default compiled reward and the user-reward hook), ``config`` (validated arguments),
``episodes`` (trims, turbulence bank, episode starts), ``kernel`` (the compiled control step),
``batch`` (N environments in flat arrays), ``env`` / ``vector`` / ``sb3`` (the API adapters),
``render``.
"""

from ..registration import ENV_ID, MAX_EPISODE_STEPS, register
from .batch import ActionError, EnvBatch
from .config import TaskConfig, TaskError
from .env import TetheredAerostatEnv
from .reward import DEFAULT_WEIGHTS, REWARD_TERMS, reward_table
from .sb3 import sb3_vec_env
from .spaces import CHANNELS, OBS_INDEX, observation_table
from .vector import TetheredAerostatVectorEnv

__all__ = ["ActionError", "CHANNELS", "DEFAULT_WEIGHTS", "ENV_ID", "EnvBatch",
           "MAX_EPISODE_STEPS", "OBS_INDEX", "REWARD_TERMS", "TaskConfig", "TaskError",
           "TetheredAerostatEnv", "TetheredAerostatVectorEnv", "observation_table", "register",
           "reward_table", "sb3_vec_env"]
