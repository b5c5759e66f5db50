"""Gymnasium environments: ``TetheredAerostat-v0`` (single and native vector) and the SB3 adapter."""

from ..registration import ENV_ID, MAX_EPISODE_STEPS, register
from .batch import ActionError, EnvBatch
from .env import TetheredAerostatEnv
from .spaces import CHANNELS, DEFAULT_WEIGHTS, REWARD_TERMS, observation_table
from .task import TaskConfig, TaskError
from .vector import TetheredAerostatVectorEnv, sb3_vec_env

__all__ = ["ActionError", "CHANNELS", "DEFAULT_WEIGHTS", "ENV_ID", "EnvBatch", "MAX_EPISODE_STEPS", "REWARD_TERMS",
           "TaskConfig", "TaskError", "TetheredAerostatEnv", "TetheredAerostatVectorEnv",
           "observation_table", "register", "sb3_vec_env"]
