"""Realised turbulence at the aerostat in the environment: the intensity sigma_u / U(h) that
an intensity class produces, pooled over episodes, against its target, and the air-inertia
force the turbulence puts on the hull."""

from __future__ import annotations

import math

import numpy as np

from ..envs.vector import TetheredAerostatVectorEnv
from ..params import Params
from ..physics.core import air_inertia_load, rotation_matrix
from ..physics.packing import pack_params
from ..physics.wind import (
    W_DIRC,
    W_DIRS,
    W_FIELD_DT,
    W_FIELD_T0,
    W_TAYLOR_U,
    air_acceleration,
    air_velocity,
    mean_speed,
)
from ..wind.presets import resolve_turbulence

SAMPLE_DT = 0.2  # [s] sampling step of the air velocity at the aerostat (the control step)


def realised_intensity(turbulence, wind_speed: float, episodes: int = 20,
                       duration: float = 120.0, first_seed: int = 100) -> dict:
    """Turbulence intensity at the aerostat's trim CM, pooled over ``episodes`` episodes.

    Parameters
    ----------
    turbulence : str, TurbulenceConfig or dict
        The environment's ``turbulence`` argument (an intensity class or a config).
    wind_speed : float
        Episode wind speed [m/s] (a reset option, on the 0.1 m/s grid).
    episodes : int
        Number of episodes (seeds ``first_seed``, ``first_seed + 1``, ...).
    duration : float
        Length of each episode's record [s].
    first_seed : int
        Seed of the first episode.

    Returns
    -------
    dict
        ``realised`` (pooled sigma_u / U(h), the along-wind fluctuation about the known zero
        mean), ``target`` (the class's sigma_u / U(h) in that wind), ``speed_at_height``
        U(h) [m/s] and ``samples``.
    """
    env = TetheredAerostatVectorEnv(num_envs=episodes, turbulence=turbulence,
                                    perturbation="none", wind_speed=(wind_speed, wind_speed))
    env.reset(seed=list(range(first_seed, first_seed + episodes)))
    b = env.batch
    cfg = resolve_turbulence(turbulence)
    times = np.arange(0.0, duration, SAMPLE_DT)
    fluct = []
    targets = []
    for i in range(episodes):
        wp, wf = b.wind[i], b.bank[b.field_index[i]]
        x, y, z = b.trim_state[i][b.layout.cm_pos]
        ux = np.array([air_velocity(x, y, z, t, wp, wf) for t in times])
        along = ux[:, 0] * wp[W_DIRC] + ux[:, 1] * wp[W_DIRS]
        fluct.append(along - mean_speed(z, wp))
        uh = float(mean_speed(cfg.reference_height, wp))
        targets.append(cfg.for_wind(wp).sigma_u / uh)
    env.close()
    u = np.concatenate(fluct)
    uh = float(mean_speed(cfg.reference_height, b.wind[0]))
    return {"realised": float(np.sqrt(np.mean(u * u)) / uh), "target": float(np.mean(targets)),
            "speed_at_height": uh, "samples": int(u.size)}


def field_intensity(turbulence, wind_speed: float, params: Params | None = None) -> dict:
    """Realised sigma of u, v, w at the aerostat's trim CM over the whole turbulence bank, as
    fractions of the class's targets: every bank field read through its full period at the
    field's own time step (no sampling spread: a pooled set of episodes scatters about these
    by several per cent, :func:`realised_intensity`). The bank's rows are normalised to unit
    variance and the sampler keeps it between rows, so each ratio is 1 up to the row
    correlation's variation with height.

    Returns ``ratios`` (u, v, w), the CM height ``height`` [m] and ``fields`` (bank size)."""
    env = TetheredAerostatVectorEnv(num_envs=1, turbulence=turbulence, perturbation="none",
                                    wind_speed=(wind_speed, wind_speed), params=params)
    env.reset(seed=0)
    b = env.batch
    cfg = resolve_turbulence(turbulence)
    wp = b.wind[0].copy()
    x, y, z = b.trim_state[0][b.layout.cm_pos]
    xa = x * wp[W_DIRC] + y * wp[W_DIRS]
    n_times = b.bank.shape[2]
    # the field's own samples at this station: t0 + j dt, delayed by the station's xa / U_a
    times = wp[W_FIELD_T0] + np.arange(n_times) * wp[W_FIELD_DT] + xa / wp[W_TAYLOR_U]
    squares = np.zeros(3)
    for wf in b.bank:
        a = np.array([air_velocity(x, y, z, t, wp, wf) for t in times])
        along = a[:, 0] * wp[W_DIRC] + a[:, 1] * wp[W_DIRS] - mean_speed(z, wp)
        across = -a[:, 0] * wp[W_DIRS] + a[:, 1] * wp[W_DIRC]
        squares += [np.mean(along ** 2), np.mean(across ** 2), np.mean(a[:, 2] ** 2)]
    targets = np.array(cfg.for_wind(wp).sigmas)
    fields = b.bank.shape[0]
    env.close()
    return {"ratios": tuple(float(r) for r in np.sqrt(squares / fields) / targets),
            "height": float(z), "fields": int(fields)}


def air_inertia_force(params: Params, wp: np.ndarray, wf: np.ndarray, point, duration: float,
                      dt: float = SAMPLE_DT) -> dict:
    """RMS and peak air-inertia force [N] on the configured hull held at ``point`` with its
    axis along the mean wind: the compiled core's load
    (:func:`aerostat_gym.physics.core.air_inertia_load`, (1 + k_i) rho V a_i along body axis i,
    a the air acceleration averaged over the hull length), sampled every ``dt`` over
    ``duration`` seconds.

    Parameters
    ----------
    params : the aerostat (volume, added-mass coefficients, hull length).
    wp, wf : wind-parameter vector and turbulence field (:func:`aerostat_gym.wind.build_wind`).
    point : (x, y, z) inertial position of the hull's centre of buoyancy [m].
    duration, dt : record length and sampling step [s].

    Returns
    -------
    dict
        RMS force along, across and normal to the wind [N], peak force magnitude [N] and the
        RMS air acceleration [m/s^2].
    """
    x, y, z = point
    p = pack_params(params)
    R = rotation_matrix(0.0, 0.0, math.atan2(wp[W_DIRS], wp[W_DIRC])).reshape(-1)
    times = np.arange(0.0, duration, dt)
    a = np.array([air_acceleration(x, y, z, t, wp, wf, params.aerostat.length) for t in times])
    f = np.array([air_inertia_load(t, x, y, z, p, R, wp, wf) for t in times]).reshape(-1, 3)
    mag = np.linalg.norm(f, axis=1)
    return {"rms_axial_n": float(np.sqrt(np.mean(f[:, 0] ** 2))),
            "rms_lateral_n": float(np.sqrt(np.mean(f[:, 1] ** 2))),
            "rms_vertical_n": float(np.sqrt(np.mean(f[:, 2] ** 2))),
            "peak_n": float(mag.max()) if mag.size else 0.0,
            "rms_air_acceleration_m_s2": float(np.sqrt(np.mean(np.sum(a * a, axis=1))))}
