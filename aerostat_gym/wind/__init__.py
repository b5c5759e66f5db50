"""Wind for aerostat-gym: mean profiles, seeded turbulence (Dryden, von Karman), coherent fields
along the tether and the hull (Veers method, IEC coherence, Taylor delay) and discrete gusts.

The physics reads wind only through :func:`aerostat_gym.physics.wind.air_velocity`; this package
builds its inputs once per episode with :func:`build_wind`.
"""

from .field import build_wind, check_covers, field_heights, field_times, mean_only, mean_vector
from .presets import PRESETS, TurbulenceConfig, describe, get_preset, resolve_turbulence

__all__ = [
    "PRESETS",
    "TurbulenceConfig",
    "build_wind",
    "check_covers",
    "describe",
    "field_heights",
    "field_times",
    "get_preset",
    "mean_only",
    "mean_vector",
    "resolve_turbulence",
]
