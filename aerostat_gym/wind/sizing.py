"""The turbulence field sized from the configured aerostat, tether and winch, and the TOML's
turbulence keys (``wind.turbulence``, ``wind.turbulence_model``,
``wind.turbulence_reference_height``) as the one source of the environment's and the
simulator's turbulence.

The presets of :mod:`aerostat_gym.wind.presets` carry a grid sized for the baseline (a 300 m
tether); :func:`field_extent` replaces it by one that serves any configuration:

- heights from the winch up to above the highest point the aerostat can reach, i.e. fully
  paid out (``winch.max_length``) and straight up: the confluence point at
  max_length (1 + strain), the CM |leash_z| above it, and the hull and fins above the CM;
- along-wind extent downwind from the longest tether (``winch.max_length``) plus the hull.
"""

from __future__ import annotations

import math

import numpy as np

from ..params import Params
from .field import build_wind
from .presets import PRESETS, TurbulenceConfig, resolve_turbulence

#: Name of the turbulence argument that reads the parameter file's turbulence keys.
FROM_CONFIG = "config"


def highest_point(params: Params) -> float:
    """Height above the anchor [m] of the highest point the aerostat can reach: tether at the
    winch's maximum length, stretched by the net lift, straight up, and the top of the hull
    or the upper fin's tip above the CM."""
    a, d = params.aerostat, params.derived
    stretch = 1.0 + d.net_lift / d.EA
    body_top = max([a.nose_position[2], a.cb_position[2]]
                   + [pan.cp_position[2] for pan in params.fins.panels]) + 0.5 * a.diameter
    return params.winch.max_length * stretch + abs(a.leash_z) + body_top


def field_extent(params: Params, dz: float) -> dict:
    """Field-grid fields of :class:`TurbulenceConfig` for ``params``: ``z_min`` (the anchor),
    ``z_max`` (one grid step ``dz`` above :func:`highest_point`), ``downwind_extent`` (longest
    tether plus the hull length) and ``reference_height`` (``wind.turbulence_reference_height``
    clipped into the field)."""
    z0 = float(params.tether.anchor_position[2])
    z_top = z0 + highest_point(params)
    rows = (z_top - z0) / dz
    if not math.isfinite(rows):
        raise ValueError(f"turbulence dz = {dz!r} m is too small for the field's "
                         f"{z_top - z0:g} m of heights")
    z_max = z0 + dz * (math.ceil(rows) + 1)
    ref = min(max(params.wind.turbulence_reference_height, z0), z_max)
    return {"z_min": z0, "z_max": z_max, "reference_height": ref,
            "downwind_extent": float(params.winch.max_length + params.aerostat.length)}


def sized_turbulence(params: Params, turbulence=FROM_CONFIG) -> TurbulenceConfig:
    """The turbulence of one episode, sized from ``params``.

    Parameters
    ----------
    params : Params
        The configuration (its turbulence keys are read when ``turbulence`` is ``"config"``).
    turbulence : str, dict, TurbulenceConfig or None
        ``"config"`` (default): the preset ``wind.turbulence`` with the spectrum
        ``wind.turbulence_model``; a preset name or a dict of fields (as the environment's
        ``turbulence`` argument); a :class:`TurbulenceConfig` is taken as given (its own grid).

    Returns
    -------
    TurbulenceConfig with the field grid of :func:`field_extent`; fields set explicitly in a
    dict keep their values.
    """
    if isinstance(turbulence, TurbulenceConfig):
        return turbulence
    explicit = set(turbulence) if isinstance(turbulence, dict) else set()
    if turbulence == FROM_CONFIG:
        cfg = resolve_turbulence(params.wind.turbulence)
        if params.wind.turbulence_model != cfg.model:
            cfg = cfg.replace(model=params.wind.turbulence_model)
    elif isinstance(turbulence, str) and turbulence not in PRESETS:
        raise ValueError(f"unknown turbulence preset {turbulence!r}; choose one of "
                         f"{[*PRESETS, FROM_CONFIG]} ('{FROM_CONFIG}': the parameter file's "
                         "wind.turbulence)")
    else:
        cfg = resolve_turbulence(turbulence)
    sized = {k: v for k, v in field_extent(params, cfg.dz).items() if k not in explicit}
    return cfg.replace(**sized)


def configured_wind(params: Params, duration: float, rng: np.random.Generator | None = None,
                    speed: float | None = None, gust: dict | None = None):
    """(wp, wf) for :func:`aerostat_gym.sim.simulate` (``wind=``) from the parameter file alone:
    its mean wind (``wind.*``, at ``speed`` if given) and its turbulence keys, on the sized grid.
    The same source as the environment's ``turbulence="config"``."""
    mean = {k: getattr(params.wind, k) for k in ("profile", "speed", "direction_deg",
                                                 "reference_height", "shear_exponent",
                                                 "roughness_length")}
    if speed is not None:
        mean["speed"] = float(speed)
    return build_wind(mean, sized_turbulence(params), duration, rng, gust)
