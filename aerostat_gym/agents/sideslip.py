"""Yaw departures at large sideslip: the static yaw moment against a yaw offset from the trim,
and how often passive-winch episodes in turbulence exceed a sideslip bound
(``scripts/sideslip_departures.py`` prints both)."""

from __future__ import annotations

import numpy as np

from ..analysis.trim import find_equilibrium
from ..envs.spaces import CHANNELS, OBS_WIND_X, OBS_WIND_Y, OBS_WIND_Z
from ..envs.vector import TetheredAerostatVectorEnv
from ..params import load_params
from ..physics.core import rotation_matrix
from ..sim import Model

OFFSETS_DEG = (5, 10, 15, 20, 30, 45, 60, 80, 100)
WIND = [OBS_WIND_X, OBS_WIND_Y, OBS_WIND_Z]  # measured air velocity at the CM


def yaw_curve(stall_deg: float, wind_speed: float = 8.0, params=None) -> list[float]:
    """Yaw acceleration dr/dt [rad/s^2] at the trim with psi offset by each of OFFSETS_DEG, for
    ``params`` (default: the baseline) with the fin stall angle set."""
    p = (params or load_params()).replace(**{"fins.alpha_stall_deg": stall_deg})
    eq = find_equilibrium(p, wind_speed)
    model = Model(p, wind=wind_speed)
    lay = model.layout
    out = []
    for deg in OFFSETS_DEG:
        x = eq.x.copy()
        x[lay.euler.start + 2] += np.radians(deg)
        out.append(float(model.rhs(x)[lay.rates.start + 2]))
    return out


def sideslip(euler: np.ndarray, v_rel: np.ndarray) -> np.ndarray:
    """Sideslip [deg] of the body velocity relative to the air, rows of Z-Y-X Euler angles."""
    R = np.array([rotation_matrix(*e) for e in euler])  # body to inertial, one per row
    body = np.einsum("nij,ni->nj", R, v_rel)  # R^T v_rel: body-frame components
    return np.degrees(np.arctan2(np.abs(body[:, 1]), body[:, 0]))


def max_sideslip(turbulence: str, wind_speed: float, episodes: int, params=None) -> np.ndarray:
    """Largest sideslip [deg] of each passive-winch episode (120 s, seeds 100, 101, ...) in the
    environment of ``params`` (default: the baseline)."""
    env = TetheredAerostatVectorEnv(num_envs=episodes, max_episode_steps=600, observation="full",
                                    turbulence=turbulence, perturbation="none", params=params)
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
