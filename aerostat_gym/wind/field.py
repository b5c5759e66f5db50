"""The one entry point the simulator and the environment call: :func:`build_wind`.

``build_wind(mean, turbulence, duration, rng, gust)`` returns ``(wp, wf)`` for
:func:`aerostat_gym.physics.wind.air_velocity`: the packed wind-parameter vector and the
turbulence field (n_heights, n_times, 3). The same generator state gives a bit-identical field.
The trim uses the mean wind only (``wp`` with turbulence and gust off, or :func:`mean_only`).
"""

from __future__ import annotations

import math

import numpy as np

from ..physics.wind import (
    NO_FIELD,
    W_FIELD_DT,
    W_FIELD_DZ,
    W_FIELD_T0,
    W_FIELD_XDOWN,
    W_FIELD_XUP,
    W_FIELD_Z0,
    W_GUST_ON,
    W_SIZE,
    W_TAYLOR_U,
    W_TURB_ON,
    derived_consistent,
    pack_wind,
    set_advection,
    set_field,
    set_gust,
    set_row_decorrelation,
)
from .dryden import dryden_point_field
from .presets import TurbulenceConfig, resolve_turbulence
from .synthesis import fft_length, veers_field

MEAN_KEYS = ("profile", "speed", "direction_deg", "reference_height", "shear_exponent",
             "roughness_length")


def build_wind(mean, turbulence: str | TurbulenceConfig | dict | None = "none",
               duration: float = 600.0, rng: np.random.Generator | None = None,
               gust: dict | None = None, *, reference_height: float | None = None
               ) -> tuple[np.ndarray, np.ndarray]:
    """Wind-parameter vector and turbulence field for one episode.

    Parameters
    ----------
    mean : dict, WindParams-like or ndarray
        Mean wind: a dict with keys among ``profile`` ('uniform', 'power', 'log'), ``speed``
        [m/s] at ``reference_height`` [m], ``direction_deg`` [deg, heading the wind blows
        toward], ``shear_exponent`` [-], ``roughness_length`` [m]; an object with those
        attributes (:class:`aerostat_gym.params.WindParams`); or a vector from ``pack_wind``.
    turbulence : str, TurbulenceConfig, dict or None
        Intensity class ('none', 'light', 'moderate', 'severe': sigma follows this mean wind,
        see :mod:`aerostat_gym.wind.presets`), a config, or a dict of config fields (key
        'preset' picks the base; explicit sigma_* make it 'fixed'). None means 'none'.
    duration : float
        Episode length [s] the field must cover (> 0).
    rng : numpy.random.Generator
        Source of all randomness (required when the turbulence is on).
    gust : dict, optional
        1 - cos gust: ``amplitude`` [m/s] (scalar along the mean wind, or (u, v, w)),
        ``length`` [m] or ``duration`` [s] (length = duration U_a), ``onset`` [s] (time the gust
        front reaches ``position``, default 0 s) and ``position`` [m] (along-wind station,
        default 0 = the anchor). A point at along-wind x sees the peak at
        onset + (x - position) / U_a + length / (2 U_a).
    reference_height : float, optional
        Overrides ``turbulence.reference_height`` [m] (the aerostat's nominal height).

    Returns
    -------
    wp : ndarray, shape (W_SIZE,)
    wf : ndarray, shape (n_heights, n_times, 3), or ``NO_FIELD`` when the turbulence is off.

    Notes
    -----
    U_a = max(U(reference_height), min_advection_speed) advects the frozen field and the gust.
    The field's time grid starts at -downwind_extent / U_a and ends at or after
    duration + upwind_extent / U_a, so every point within those along-wind extents is served
    for 0 <= t <= duration (:func:`check_covers` verifies it).
    """
    cfg = resolve_turbulence(turbulence)
    if reference_height is not None:
        cfg = cfg.replace(reference_height=reference_height)
    if not (isinstance(duration, (int, float)) and math.isfinite(duration) and duration > 0):
        raise ValueError(f"wind field duration must be a finite number > 0 [s], got {duration!r}")
    wp = mean_vector(mean)
    cfg = cfg.for_wind(wp)  # a wind-scaled class: its sigmas in this mean wind
    ua = set_advection(wp, cfg.reference_height, cfg.min_advection_speed)
    if gust is not None:
        _apply_gust(wp, gust, ua)
    if cfg.is_off:
        return wp, NO_FIELD
    if not isinstance(rng, np.random.Generator):
        raise TypeError(f"turbulence needs a numpy.random.Generator, got {type(rng).__name__}")
    return wp, _add_field(wp, cfg, ua, float(duration), rng)


def _add_field(wp: np.ndarray, cfg: TurbulenceConfig, ua: float, duration: float,
               rng: np.random.Generator) -> np.ndarray:
    """Generate the field covering [-x_down / U_a, duration + x_up / U_a] and record it in wp."""
    t0 = -cfg.downwind_extent / ua
    n = fft_length((duration - t0 + cfg.upwind_extent / ua) / cfg.dt + 1.0)
    if cfg.method == "filter":
        wf = dryden_point_field(cfg, ua, n, rng)
        z0 = cfg.reference_height
    else:
        wf = veers_field(cfg, ua, n, rng)
        z0 = cfg.z_min
    set_field(wp, z0, cfg.dz, t0, cfg.dt, cfg.downwind_extent, cfg.upwind_extent)
    set_row_decorrelation(wp, row_decorrelation(wf, z0, cfg.dz, cfg.reference_height))
    return wf


def row_decorrelation(fields: np.ndarray, z0: float, dz: float, height: float) -> tuple:
    """1 - the correlation of the two field rows around ``height`` [m], for u, v, w: what the
    sampler needs to keep the rows' variance between them (:data:`W_FIELD_DU`). ``fields`` is
    one field (rows, times, 3) or a bank of them (fields, rows, times, 3); rows from ``z0`` [m]
    every ``dz`` [m]. A single row (a point field) needs no correction: zeros."""
    return decorrelation_at(pair_decorrelations(fields), z0, dz, height)


def decorrelation_at(pairs: np.ndarray, z0: float, dz: float, height: float) -> tuple:
    """The row pair around ``height`` [m] of :func:`pair_decorrelations`' ``pairs`` (rows from
    ``z0`` every ``dz`` [m]; the edge pair beyond the grid), as (u, v, w); zeros for none."""
    if pairs.shape[0] == 0:
        return (0.0, 0.0, 0.0)
    k = int(min(max(math.floor((height - z0) / dz), 0), pairs.shape[0] - 1))
    return tuple(float(v) for v in pairs[k])


def pair_decorrelations(fields: np.ndarray) -> np.ndarray:
    """1 - rho of every pair of adjacent rows (rows - 1, 3) of a field or a bank of fields
    (see :func:`row_decorrelation`), clipped to [0, 1]."""
    bank = fields if fields.ndim == 4 else fields[None]
    if bank.shape[1] < 2 or bank.shape[2] == 0:
        return np.zeros((0, 3))
    lower, upper = bank[:, :-1], bank[:, 1:]
    cross = np.einsum("nktc,nktc->kc", lower, upper)
    power = np.einsum("nktc,nktc->kc", bank, bank)
    norm = np.sqrt(power[:-1] * power[1:])
    rho = np.divide(cross, norm, out=np.ones_like(cross), where=norm > 0.0)
    return np.clip(1.0 - rho, 0.0, 1.0)


def mean_vector(mean) -> np.ndarray:
    """Packed mean-wind vector (no gust, no turbulence) from a dict, WindParams-like or vector."""
    if isinstance(mean, np.ndarray):
        if mean.shape != (W_SIZE,):
            raise ValueError(f"a packed wind vector must have shape ({W_SIZE},), got {mean.shape}")
        return mean_only(mean)
    if isinstance(mean, dict):
        unknown = sorted(set(mean) - set(MEAN_KEYS))
        if unknown:
            raise ValueError(f"unknown mean-wind key(s) {unknown}; known: {list(MEAN_KEYS)}")
        return pack_wind(**mean)
    return pack_wind(**{k: getattr(mean, k) for k in MEAN_KEYS})


def mean_only(wp: np.ndarray) -> np.ndarray:
    """Copy of ``wp`` with gust and turbulence switched off (what the trim should see)."""
    out = np.array(wp, dtype=float)
    out[W_GUST_ON] = 0.0
    out[W_TURB_ON] = 0.0
    return out


def _apply_gust(wp: np.ndarray, gust: dict, ua: float) -> None:
    """Parse the gust dict (see :func:`build_wind`) and pack it."""
    known = {"amplitude", "length", "duration", "onset", "position"}
    unknown = sorted(set(gust) - known)
    if unknown:
        raise ValueError(f"unknown gust key(s) {unknown}; known: {sorted(known)}")
    if ("length" in gust) == ("duration" in gust):
        raise ValueError("a gust needs exactly one of 'length' [m] or 'duration' [s]")
    length = gust["length"] if "length" in gust else gust["duration"] * ua
    amp = np.broadcast_to(np.asarray(gust.get("amplitude", 0.0), dtype=float), (3,)).copy()
    if np.ndim(gust.get("amplitude", 0.0)) == 0:
        amp[1:] = 0.0
    set_gust(wp, tuple(amp), float(length), float(gust.get("onset", 0.0)),
             float(gust.get("position", 0.0)))


def field_times(wp: np.ndarray, wf: np.ndarray) -> np.ndarray:
    """Times of the field samples [s] (at the anchor's along-wind station)."""
    return wp[W_FIELD_T0] + wp[W_FIELD_DT] * np.arange(wf.shape[1])


def field_heights(wp: np.ndarray, wf: np.ndarray) -> np.ndarray:
    """Heights of the field rows [m]."""
    return wp[W_FIELD_Z0] + wp[W_FIELD_DZ] * np.arange(wf.shape[0])


def check_covers(wp: np.ndarray, wf: np.ndarray, t_end: float, t_start: float = 0.0) -> None:
    """Raise ``ValueError`` unless the field serves every point in its extents over [t_start, t_end].

    A point at along-wind coordinate x reads the field at t - x / U_a, so the field must span
    [t_start - x_down / U_a, t_end + x_up / U_a]. Without turbulence this always passes.
    """
    if wp[W_TURB_ON] == 0.0:
        return
    if wf.ndim != 3 or wf.shape[2] != 3 or wf.shape[1] < 2:
        raise ValueError(f"turbulence is on but the field has shape {wf.shape}; "
                         "expected (n_heights, n_times >= 2, 3)")
    if not derived_consistent(wp):
        raise ValueError("the wind vector's derived slots (1/dz, 1/dt, 1/(U_a dt)) do not match "
                         "dz, dt and U_a: set them with set_field / set_advection, not by hand")
    ua = wp[W_TAYLOR_U]
    need_lo = t_start - wp[W_FIELD_XDOWN] / ua
    need_hi = t_end + wp[W_FIELD_XUP] / ua
    have_lo = wp[W_FIELD_T0]
    have_hi = have_lo + wp[W_FIELD_DT] * (wf.shape[1] - 1)
    if need_lo < have_lo - 1e-9 or need_hi > have_hi + 1e-9:
        raise ValueError(
            f"the turbulence field covers t in [{have_lo:.3f}, {have_hi:.3f}] s but an episode "
            f"over [{t_start:g}, {t_end:g}] s needs [{need_lo:.3f}, {need_hi:.3f}] s (Taylor delay "
            f"of points {wp[W_FIELD_XDOWN]:g} m downwind to {wp[W_FIELD_XUP]:g} m upwind at "
            f"U_a = {ua:.3f} m/s): build the wind with duration >= {t_end:g} s")
