"""Yaw departures at large sideslip: the static yaw moment against a yaw offset from the trim,
and how often passive-winch episodes in turbulence exceed a sideslip bound
(``scripts/sideslip_departures.py`` prints both)."""

from __future__ import annotations

import numpy as np

from ..analysis.directional import static_yaw_acceleration
from ..analysis.trim import find_equilibrium
from ..envs.spaces import CHANNELS, OBS_WIND_X, OBS_WIND_Y, OBS_WIND_Z
from ..envs.vector import TetheredAerostatVectorEnv
from ..params import apply_overrides, load_params
from ..physics.core import rotation_matrix
from ..sim import Model

OFFSETS_DEG = (5, 10, 15, 20, 30, 45, 60, 75, 90)
WIND = [OBS_WIND_X, OBS_WIND_Y, OBS_WIND_Z]  # measured air velocity at the CM


def yaw_curve(wind_speed: float = 8.0, overrides: dict | None = None,
              offsets=OFFSETS_DEG, params=None) -> list[float]:
    """Static yaw acceleration dr/dt [rad/s^2] at the trim with psi offset by each yaw offset.

    Parameters
    ----------
    wind_speed : float
        Uniform wind speed [m/s] of the trim.
    overrides : dict, optional
        Parameter overrides (dotted keys, e.g. ``{"fins.post_stall": "flat"}``).
    offsets : sequence of float
        Yaw offsets from the trim heading [deg]; negative results restore.
    params : Params, optional
        The aerostat (default: the baseline); ``overrides`` apply to it.
    """
    p = apply_overrides(params or load_params(), overrides or {})
    eq = find_equilibrium(p, wind_speed)
    return static_yaw_acceleration(Model(p, wind=wind_speed), eq.x, offsets).tolist()


def sideslip(euler: np.ndarray, v_rel: np.ndarray) -> np.ndarray:
    """Sideslip [deg] of the body velocity relative to the air, rows of Z-Y-X Euler angles."""
    R = np.array([rotation_matrix(*e) for e in euler])  # body to inertial, one per row
    body = np.einsum("nij,ni->nj", R, v_rel)  # R^T v_rel: body-frame components
    return np.degrees(np.arctan2(np.abs(body[:, 1]), body[:, 0]))


def max_sideslip(turbulence: str, wind_speed: float, episodes: int,
                 overrides: dict | None = None, params=None) -> np.ndarray:
    """Largest sideslip [deg] of each passive-winch episode (120 s, seeds 100, 101, ...).

    Parameters
    ----------
    turbulence : str
        The environment's turbulence (an intensity class or a config).
    wind_speed : float
        Episode wind speed [m/s].
    episodes : int
        Number of episodes.
    overrides : dict, optional
        Parameter overrides (dotted keys, e.g. ``{"aerostat.air_inertia": False}``).
    params : Params, optional
        The aerostat (default: the baseline).
    """
    env = TetheredAerostatVectorEnv(num_envs=episodes, max_episode_steps=600, observation="full",
                                    turbulence=turbulence, perturbation="none", params=params,
                                    overrides=overrides)
    obs, _ = env.reset(seed=list(range(100, 100 + episodes)),
                       options={"wind_speed": [wind_speed] * episodes})
    b, lay = env.batch, env.batch.layout
    scale = np.array([CHANNELS[i].scale for i in WIND])
    worst = np.zeros(episodes)
    for _ in range(600):
        obs, *_ = env.step(np.zeros((episodes, 1), np.float32))
        v_rel = b.state[:, lay.cm_vel] - obs[:, WIND] * scale
        worst = np.maximum(worst, sideslip(b.state[:, lay.euler], v_rel))
    env.close()
    return worst
