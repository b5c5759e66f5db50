"""Pendulum damping from a record that also carries a slow non-oscillatory mode.

A winch controller with a length-restoring loop (the modal controller's 30 s pole, the LQR's
length integral) adds a real, slowly decaying mode to the along-wind CM displacement. The
single damped sinusoid of :func:`aerostat_gym.agents.metrics.fit_damped_sinusoid` then absorbs
that drift into the pendulum and, for a well-damped pendulum whose oscillation is gone within a
period, reads its damping low: on the linear closed loops of a 10 m swing it finds 0.568
(modal, designed 0.60), 0.746 (modal, 0.85), 0.322 (LQR, eigenvalue 0.344) and 0.475 (LQR,
0.611). :func:`fit_pendulum_with_drift` fits

    y = c + e^{-sigma t} (a cos w_d t + b sin w_d t) + d e^{-lambda t}

and finds 0.600, 0.854, 0.341 and 0.582 on the same records.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import least_squares

from .metrics import DampedFit, _failed, fit_damped_sinusoid

#: Start values of the drift's decay rate lambda [1/s] (time constants 10 to 120 s).
DRIFT_RATES = (1.0 / 10.0, 1.0 / 30.0, 1.0 / 60.0, 1.0 / 120.0)


def _model(q, t):
    c, a, b, sg, wd, d, lam = q
    return c + np.exp(np.clip(-sg * t, -700, 700)) * (a * np.cos(wd * t) + b * np.sin(wd * t)) \
        + d * np.exp(np.clip(-lam * t, -700, 700))


#: Start values of the pendulum damping ratio for the grid of starts.
START_ZETAS = (0.1, 0.3, 0.5, 0.7, 0.85)
#: Starts refined by least squares (the lowest linear-residual nodes of the grid).
N_REFINED = 4


def _starts(tt: np.ndarray, y: np.ndarray, f0: DampedFit) -> list[np.ndarray]:
    """Grid of (zeta, period, lambda) starts around the single-sinusoid fit; at each node the
    linear coefficients (c, a, b, d) are solved exactly and the nodes with the smallest
    residual are returned as full parameter vectors."""
    nodes = []
    for period in (f0.period, f0.damped_period, 0.7 * f0.period):
        if not (math.isfinite(period) and period > 0):
            continue
        for z in (f0.zeta, *START_ZETAS):
            z = min(max(z, 0.0), 0.97)
            wn = 2.0 * math.pi / period
            sg, wd = z * wn, wn * math.sqrt(1.0 - z * z)
            for lam in DRIFT_RATES:
                e = np.exp(-sg * tt)
                M = np.column_stack([np.ones_like(tt), e * np.cos(wd * tt), e * np.sin(wd * tt),
                                     np.exp(-lam * tt)])
                coef, *_ = np.linalg.lstsq(M, y, rcond=None)
                sse = float(np.sum((M @ coef - y) ** 2))
                c, a, b, d = coef
                nodes.append((sse, np.array([c, a, b, sg, wd, d, lam])))
    nodes.sort(key=lambda n: n[0])
    return [q for _, q in nodes[:N_REFINED]]


def fit_pendulum_with_drift(t, y, period_guess: float | None = None) -> DampedFit:
    """Damped sinusoid plus one real exponential, fitted by least squares.

    Parameters
    ----------
    t : array_like
        Sample times [s], increasing.
    y : array_like
        Samples (e.g. along-wind CM displacement from trim [m]).
    period_guess : float or None
        Rough damped period [s] for the single-sinusoid start.

    Returns
    -------
    DampedFit
        zeta, natural period, amplitude, offset and r2 of the oscillatory part (the drift is
        fitted and dropped); NaNs with a reason on failure. Never raises.

    Notes
    -----
    Starts: a grid around :func:`fit_damped_sinusoid`'s answer (its natural and damped periods
    and 0.7 times the former; its zeta and :data:`START_ZETAS`; :data:`DRIFT_RATES`) with the
    four linear coefficients solved exactly at each node; the :data:`N_REFINED` best nodes are
    refined and the lowest residual wins. lambda is bounded to
    [1e-4, 10 sigma_max] and kept apart from the oscillation only by the model's form: a drift
    that decays as fast as the oscillation is indistinguishable from it, and the fit then
    reports the single-mode answer.
    """
    try:
        t = np.asarray(t, float).ravel()
        y = np.asarray(y, float).ravel()
        keep = np.isfinite(t) & np.isfinite(y)
        t, y = t[keep], y[keep]
        f0 = fit_damped_sinusoid(t, y, period_guess)
        if not f0.ok:
            return f0
        tt = t - t[0]
        span = float(np.ptp(y))
        wmax = math.pi / float(np.median(np.diff(tt)))
        lo = [-np.inf, -np.inf, -np.inf, -1.0, 1e-9, -np.inf, 1e-4]
        hi = [np.inf, np.inf, np.inf, 10 * wmax, wmax, np.inf, 10 * wmax]
        best = None
        for q0 in _starts(tt, y, f0):
            q0 = np.clip(q0, np.array(lo) + 1e-12, np.array(hi) - 1e-12)
            sol = least_squares(lambda q: (_model(q, tt) - y) / span, q0, bounds=(lo, hi),
                                x_scale="jac", max_nfev=5000)
            if best is None or sol.cost < best.cost:
                best = sol
        c, a, b, sg, wd, _, _ = best.x
        sst = float(np.sum((y - np.mean(y)) ** 2))
        r2 = 1.0 - float(np.sum((_model(best.x, tt) - y) ** 2)) / sst
        if not (np.all(np.isfinite(best.x)) and math.isfinite(r2)):
            return _failed("drift fit did not converge to finite values")
        w = math.hypot(sg, wd)
        return DampedFit(zeta=float(sg / w), period=float(2 * math.pi / w),
                         amplitude=float(math.hypot(a, b)), offset=float(c), r2=float(r2),
                         damped_period=float(2 * math.pi / wd), phase=float(math.atan2(-b, a)))
    except Exception as exc:  # noqa: BLE001 - a metric must never abort an evaluation
        return _failed(f"drift fit failed: {type(exc).__name__}: {exc}")
