"""Registration of the environment's task variants (runs on ``import aerostat_gym``; imports only
Gymnasium: the environment's modules load when an environment is made).

Each task is an id, versioned in Gymnasium's style, whose registered keyword arguments fix the
conditions; ``gym.make(ID)`` reproduces them with no further arguments, and keyword arguments
passed to ``gym.make`` override them.
"""

from __future__ import annotations

ENV_ID = "TetheredAerostat-v0"
MAX_EPISODE_STEPS = 600  # 120 s at the default 0.2 s control step

#: Task id -> (registered keyword arguments, one-line description).
TASKS: dict[str, tuple[dict, str]] = {
    ENV_ID: ({}, "the default task: 3-15 m/s, moderate turbulence, mixed perturbation (swing, "
                 "pitch kick and, half the time, a 1 - cos gust)"),
    "TetheredAerostatDamping-v0": (
        {"turbulence": "none", "perturbation": "displacement"},
        "calm-air damping: 3-15 m/s steady wind, an initial swing of up to 10 m along and 5 m "
        "across the wind and a pitch kick of up to 0.05 rad"),
    "TetheredAerostatDampingNoisy-v0": (
        {"turbulence": "none", "perturbation": "displacement", "obs_noise": 0.01},
        "the damping task on noisy sensors: as TetheredAerostatDamping-v0, with Gaussian noise "
        "of 0.01 (scaled units) on every standard channel, the evaluation protocol's level "
        "(the PPO policy shipped with 0.3.0)"),
    "TetheredAerostatRealistic-v0": (
        {"turbulence": "light", "perturbation": "displacement", "randomize": True,
         "obs_noise": 0.01},
        "winch control in realistic conditions: 3-15 m/s, light turbulence (5 % intensity), an "
        "initial swing as in the damping task, the estimated parameters randomised per episode "
        "and the evaluation protocol's sensor noise (the shipped policy's task)"),
    "TetheredAerostatRealisticWeathervaning-v0": (
        {"turbulence": "light", "perturbation": "displacement", "randomize": True,
         "weathercock": True, "obs_noise": 0.01},
        "TetheredAerostatRealistic-v0 with every randomised aerostat weathercock-stable: a "
        "draw whose static yaw moment does not restore at yaw offsets up to 10 deg is drawn "
        "again (TetheredAerostatRealistic-v0 draws about 15 % that do not; in the light "
        "turbulence they sail 80-200 m across the wind and hold most of its heavy tail)"),
}


def register() -> None:
    """Register every task with Gymnasium (idempotent)."""
    import gymnasium as gym

    for task_id, (kwargs, _) in TASKS.items():
        if task_id in gym.registry:
            continue
        gym.register(id=task_id, entry_point="aerostat_gym.envs.env:TetheredAerostatEnv",
                     vector_entry_point="aerostat_gym.envs.vector:make_vec",
                     max_episode_steps=MAX_EPISODE_STEPS, kwargs=dict(kwargs))
