"""Damping ratios of named modes from a record that carries several, by a fit started at the
linear model's modes.

The pitch history of a swing-recovery run carries the pendulum (35-45 s) and two fast modes of
close period, the pitching mode and the axial-spring mode (2.0-2.8 s and 3.0-3.7 s on the
baseline at 5-15 m/s). The protocol's pitch fit (:func:`aerostat_gym.agents.metrics.
response_metrics`) reads one fast damped sinusoid for the two, the decay of their blend
(:mod:`aerostat_gym.agents.pitch_check`). :func:`fit_modes` fits

    y = c + sum_k e^{-sigma_k t} (a_k cos w_k t + b_k sin w_k t)

with one term per mode, each started at a given (zeta, natural period), the amplitudes solved
linearly at the start and then every parameter refined by least squares; on the linear braked
response of the recover scenarios it returns the eigenvalues' damping ratios (within 0.01 of
the pitching and axial-spring modes at 10 and 15 m/s, started half their damping ratio and 10 %
of their period away; ``tests/test_metrics.py``).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import least_squares

from .metrics import DampedFit, _failed, mode_fit


def _rates(zeta: float, period: float) -> tuple[float, float]:
    """(sigma, w_d) of a mode of damping ratio zeta and natural period [s]."""
    wn = 2.0 * math.pi / period
    return zeta * wn, wn * math.sqrt(1.0 - zeta * zeta)


def fit_modes(t, y, starts) -> list[DampedFit]:
    """One :class:`DampedFit` per mode of ``starts`` [(zeta, natural period [s]), ...], in the
    same order (a refined mode may move off its start: match the fits to the modes by period).
    NaNs with a reason on failure; never raises."""
    k_modes = len(starts)
    try:
        t = np.asarray(t, dtype=float).ravel()
        y = np.asarray(y, dtype=float).ravel()
        keep = np.isfinite(t) & np.isfinite(y)
        t, y = t[keep], y[keep]
        span = float(np.ptp(y)) if y.size else 0.0
        if t.size < 4 * k_modes + 4 or not span > 0:
            return [_failed("too few samples or a flat signal")] * k_modes
        if not all(math.isfinite(z) and 0 <= z < 1 and math.isfinite(p) and p > 0
                   for z, p in starts):
            return [_failed(f"mode starts must be (zeta in [0, 1), period > 0), got {starts}")
                    ] * k_modes
        tt = t - t[0]
        n_lin = 1 + 2 * k_modes

        def basis(q):
            cols = [np.ones_like(tt)]
            for k in range(k_modes):
                e = np.exp(np.clip(-q[2 * k] * tt, -700.0, 700.0))
                cols += [e * np.cos(q[2 * k + 1] * tt), e * np.sin(q[2 * k + 1] * tt)]
            return np.column_stack(cols)

        q0 = np.array([r for z, p in starts for r in _rates(z, p)])
        coef, *_ = np.linalg.lstsq(basis(q0), y, rcond=None)

        def resid(x):
            return (basis(x[n_lin:]) @ x[:n_lin] - y) / span

        dt = float(np.median(np.diff(tt)))
        wmax = math.pi / dt
        lo = np.array([-np.inf] * n_lin + [-1.0, 1e-9] * k_modes)
        hi = np.array([np.inf] * n_lin + [10 * wmax, wmax] * k_modes)
        x0 = np.clip(np.concatenate([coef, q0]), lo + 1e-12, hi - 1e-12)
        sol = least_squares(resid, x0, bounds=(lo, hi), x_scale="jac", max_nfev=8000)
        sst = float(np.sum((y - np.mean(y)) ** 2))
        r2 = 1.0 - float(np.sum((resid(sol.x) * span) ** 2)) / sst
        if not (np.all(np.isfinite(sol.x)) and math.isfinite(r2)):
            return [_failed("least-squares fit did not converge")] * k_modes
        out = []
        for k in range(k_modes):
            a, b = sol.x[1 + 2 * k], sol.x[2 + 2 * k]
            sg, wd = sol.x[n_lin + 2 * k], sol.x[n_lin + 2 * k + 1]
            out.append(mode_fit(a, b, sg, wd, sol.x[0], r2, dt))
        return out
    except Exception as exc:  # noqa: BLE001 - a metric must never abort an evaluation
        return [_failed(f"fit failed: {type(exc).__name__}: {exc}")] * k_modes


def nearest_mode(fits: list[DampedFit], period: float) -> DampedFit:
    """The fit whose natural period is nearest ``period`` [s] (a failed fit if none is ok)."""
    ok = [f for f in fits if f.ok]
    if not ok:
        return fits[0] if fits else _failed("no fit")
    return min(ok, key=lambda f: abs(f.period - period))
