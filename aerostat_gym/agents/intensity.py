"""Realised turbulence at the aerostat in the environment: the intensity sigma_u / U(h) that
an intensity class produces, pooled over episodes, against its target, and the air-inertia
force the turbulence puts on the hull."""

from __future__ import annotations

import numpy as np

from ..envs.vector import TetheredAerostatVectorEnv
from ..physics.wind import W_DIRC, W_DIRS, air_acceleration, air_velocity, mean_speed
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


def air_inertia_force(wp: np.ndarray, wf: np.ndarray, point, rho_volume: float,
                      k_axial: float, k_lateral: float, length: float, duration: float,
                      dt: float = SAMPLE_DT) -> dict:
    """RMS and peak air-inertia force [N] on a hull held at ``point`` with its axis along the
    mean wind: (1 + k1) rho V a_u along the axis, (1 + k3) rho V a_v, a_w across it, with
    a the air acceleration averaged over the hull length.

    Parameters
    ----------
    wp : ndarray
        Wind-parameter vector (:func:`aerostat_gym.wind.build_wind`).
    wf : ndarray
        Turbulence field of that wind.
    point : (float, float, float)
        Inertial position of the hull's centre of buoyancy [m].
    rho_volume : float
        Displaced air mass rho V [kg].
    k_axial : float
        Axial added-mass coefficient k1 [-].
    k_lateral : float
        Lateral added-mass coefficient k3 [-].
    length : float
        Hull length [m]: the air acceleration is averaged over it along the wind.
    duration : float
        Record length [s].
    dt : float
        Sampling step [s].

    Returns
    -------
    dict
        RMS force along, across and normal to the wind [N], peak force magnitude [N] and the
        RMS air acceleration [m/s^2].
    """
    x, y, z = point
    times = np.arange(0.0, duration, dt)
    a = np.array([air_acceleration(x, y, z, t, wp, wf, length) for t in times])
    c, s = wp[W_DIRC], wp[W_DIRS]
    au = a[:, 0] * c + a[:, 1] * s  # along the mean wind: the hull axis
    av = -a[:, 0] * s + a[:, 1] * c
    f = rho_volume * np.stack([(1.0 + k_axial) * au, (1.0 + k_lateral) * av,
                               (1.0 + k_lateral) * a[:, 2]], axis=1)
    mag = np.linalg.norm(f, axis=1)
    return {"rms_axial_n": float(np.sqrt(np.mean(f[:, 0] ** 2))),
            "rms_lateral_n": float(np.sqrt(np.mean(f[:, 1] ** 2))),
            "rms_vertical_n": float(np.sqrt(np.mean(f[:, 2] ** 2))),
            "peak_n": float(mag.max()) if mag.size else 0.0,
            "rms_air_acceleration_m_s2": float(np.sqrt(np.mean(np.sum(a * a, axis=1))))}
