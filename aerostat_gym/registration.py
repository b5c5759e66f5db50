"""Registration of ``TetheredAerostat-v0`` (runs on ``import aerostat_gym``; imports only
Gymnasium: the environment's modules load when an environment is made)."""

from __future__ import annotations

ENV_ID = "TetheredAerostat-v0"
MAX_EPISODE_STEPS = 600  # 120 s at the default 0.2 s control step


def register() -> None:
    """Register the environment with Gymnasium (idempotent)."""
    import gymnasium as gym

    if ENV_ID in gym.registry:
        return
    gym.register(id=ENV_ID, entry_point="aerostat_gym.envs.env:TetheredAerostatEnv",
                 vector_entry_point="aerostat_gym.envs.vector:make_vec",
                 max_episode_steps=MAX_EPISODE_STEPS)
