"""Cost of the wind: field generation per episode and ``air_velocity`` per call.

``bench_wind()`` is meant to be reported by ``aerostat-gym bench`` next to the right-hand-side
cost: the field's share of a step is ``calls_per_rhs * extra_ns_per_call`` over the RHS time.
"""

from __future__ import annotations

import time

import numpy as np
from numba import njit

from ..params import Params, load_params
from ..physics.wind import NO_FIELD, W_TURB_ON, air_velocity, air_velocity_batch
from ..wind.field import build_wind, mean_only


def calls_per_rhs(params: Params) -> int:
    """Wind samples per right-hand-side call: one per tether element midpoint, the hull point
    and one per fin (the points of :func:`aerostat_gym.physics.core.wind_batch`)."""
    return params.tether.n_elements + 1 + len(params.fins.panels)


def typical_points(n_tether: int = 10) -> np.ndarray:
    """Sample points [m]: tether element midpoints on a straight 300 m line to (100, 0, 280),
    the hull centre of pressure and three fins around the aerostat at (105, 0, 283)."""
    s = (np.arange(n_tether) + 0.5) / n_tether
    tether = np.stack([100.0 * s, 0.0 * s, 280.0 * s], axis=1)
    hull = np.array([[101.0, 0.0, 283.0], [110.0, 0.0, 288.0], [110.0, 4.3, 282.0],
                     [110.0, -4.3, 282.0]])
    return np.ascontiguousarray(np.vstack([tether, hull]))


# Not cached: numba's cache does not see changes in the functions a cached function calls.
@njit(error_model="numpy")
def _sample_loop(points, t_end, n_steps, wp, wf):
    """Call air_velocity at every point for n_steps times in [0, t_end); return a checksum."""
    acc = 0.0
    dt = t_end / n_steps
    for k in range(n_steps):
        t = k * dt
        for i in range(points.shape[0]):
            wx, wy, wz = air_velocity(points[i, 0], points[i, 1], points[i, 2], t, wp, wf)
            acc += wx + 0.5 * wy + 0.25 * wz
    return acc


@njit(error_model="numpy")
def _batch_loop(points, t_end, n_steps, wp, wf):
    """The same samples through air_velocity_batch on a core-like work array."""
    npts = points.shape[0]
    w = np.empty(6 * npts)
    w[: 3 * npts] = points.ravel()
    acc = 0.0
    dt = t_end / n_steps
    for k in range(n_steps):
        air_velocity_batch(k * dt, w, npts, 0, wp, wf)
        for i in range(npts):
            acc += w[3 * npts + 3 * i] + 0.5 * w[3 * npts + 3 * i + 1] + 0.25 * w[3 * npts + 3 * i + 2]
    return acc


def _ns_per_call(loop, points, t_end, n_steps, wp, wf, repeats: int) -> float:
    """Best-of-``repeats`` time per sampled point [ns]."""
    loop(points, t_end, 10, wp, wf)  # compile / warm up
    best = np.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        loop(points, t_end, n_steps, wp, wf)
        best = min(best, time.perf_counter() - t0)
    return 1e9 * best / (n_steps * points.shape[0])


def bench_wind(duration: float = 600.0, preset: str = "moderate", speed: float = 8.0,
               repeats: int = 7, n_steps: int = 50_000, seed: int = 0,
               params: Params | None = None) -> dict:
    """Field generation time and per-call cost of ``air_velocity`` with and without the field.

    Returns
    -------
    dict
        ``field_generation_s`` (median of ``repeats`` builds of a ``duration`` s field at the
        default heights), ``field_shape``, ``field_mbytes``, ``ns_per_call_mean_only``,
        ``ns_per_call_gust``, ``ns_per_call_field``, ``ns_per_call_field_gust`` (best of
        ``repeats`` loops of ``n_steps`` x 14 calls at :func:`typical_points`), the same through
        :func:`air_velocity_batch` (``ns_per_point_batch_*``) and ``extra_ns_per_rhs``
        (:func:`calls_per_rhs` x (field - mean only), per-point calls; ``params`` default: the
        baseline).
    """
    calls = calls_per_rhs(params or load_params())
    mean = {"speed": speed}
    times = []
    for r in range(repeats):
        t0 = time.perf_counter()
        wp, wf = build_wind(mean, preset, duration, np.random.default_rng(seed + r))
        times.append(time.perf_counter() - t0)
    gust = {"amplitude": (3.0, 1.0, 1.0), "length": 100.0, "onset": 1.0}
    wpg, _ = build_wind(mean, preset, duration, np.random.default_rng(seed), gust=gust)
    pts = typical_points()
    cases = {"mean_only": (mean_only(wp), NO_FIELD), "gust": (_turb_off(wpg), NO_FIELD),
             "field": (wp, wf), "field_gust": (wpg, wf)}
    cost = {k: _ns_per_call(_sample_loop, pts, duration, n_steps, *v, repeats)
            for k, v in cases.items()}
    batch = {k: _ns_per_call(_batch_loop, pts, duration, n_steps, *cases[k], repeats)
             for k in ("mean_only", "field")}
    return {"field_generation_s": float(np.median(times)), "field_shape": list(wf.shape),
            "field_mbytes": wf.nbytes / 2**20, **{f"ns_per_call_{k}": v for k, v in cost.items()},
            **{f"ns_per_point_batch_{k}": v for k, v in batch.items()},
            "calls_per_rhs": calls,
            "extra_ns_per_rhs": calls * (cost["field"] - cost["mean_only"])}


def _turb_off(wp: np.ndarray) -> np.ndarray:
    """Copy of wp with the gust kept and the turbulence off."""
    out = wp.copy()
    out[W_TURB_ON] = 0.0
    return out
