"""Realised turbulence statistics against their targets (used by the tests and the CLI).

Estimators follow the validation practice of flight simulation (NASA LaRC Dryden verification)
and wind energy (TurbSim, pyconturb):

- variance as the mean square about the known zero mean (subtracting the sample mean biases it
  low by about 2 T_int / T);
- PSD by Welch (Hann, 50 % overlap, no detrending) averaged over an ensemble, compared with the
  analytic S(f) = 2 pi Phi(2 pi f / V) / V in log-spaced bands;
- integral length scale L = U x integral of the ensemble autocorrelation;
- coherence from the ensemble-averaged cross-spectrum (single-record coherence is biased high by
  about 1 / n_averages).

Arrays hold one record per row; every leading axis is an ensemble axis.
"""

from __future__ import annotations

import numpy as np
import scipy.fft
import scipy.optimize
import scipy.signal

from ..physics.wind import W_FIELD_DT, W_FIELD_DZ, W_FIELD_Z0, W_TAYLOR_U
from .presets import TurbulenceConfig
from .spectra import correlation, temporal_psd
from .synthesis import iec_coherence

COMPONENTS = ("u", "v", "w")


def mean_square(x: np.ndarray) -> float:
    """Variance about the known zero mean: mean of x^2 over all samples."""
    return float(np.mean(np.square(x)))


def welch_psd(x: np.ndarray, dt: float, nperseg: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Ensemble-averaged one-sided Welch PSD [(m/s)^2/Hz] of records along the last axis."""
    x = np.reshape(x, (-1, np.shape(x)[-1]))
    nperseg = min(nperseg or x.shape[-1], x.shape[-1])
    f, P = scipy.signal.welch(x, fs=1.0 / dt, nperseg=nperseg, detrend=False, axis=-1)
    return f, P.mean(axis=0)


def band_ratios(f: np.ndarray, P: np.ndarray, S: np.ndarray, f_lo: float, f_hi: float,
                n_bands: int = 8) -> tuple[np.ndarray, np.ndarray]:
    """Ratio of estimated to analytic power in log-spaced bands of [f_lo, f_hi].

    Returns the geometric band centres [Hz] and mean(P) / mean(S) per band (bands without a
    frequency bin are dropped).
    """
    edges = np.geomspace(f_lo, f_hi, n_bands + 1)
    centres, ratios = [], []
    for lo, hi in zip(edges[:-1], edges[1:], strict=True):
        m = (f >= lo) & (f < hi)
        if m.any():
            centres.append(np.sqrt(lo * hi))
            ratios.append(P[m].mean() / S[m].mean())
    return np.array(centres), np.array(ratios)


def loglog_slope(f: np.ndarray, P: np.ndarray, f_lo: float, f_hi: float) -> float:
    """Least-squares slope of log P against log f over [f_lo, f_hi] (-2 Dryden, -5/3 von Karman)."""
    m = (f >= f_lo) & (f <= f_hi) & (P > 0)
    return float(np.polyfit(np.log(f[m]), np.log(P[m]), 1)[0])


def autocorrelation(x: np.ndarray, max_lag: int) -> np.ndarray:
    """Ensemble-averaged autocorrelation rho(k), k = 0..max_lag, about the known zero mean.

    Notes
    -----
    ``R(k) = mean over rows of sum_j x_j x_{j+k} / (n - k)`` (unbiased, no mean removal), by
    zero-padded FFT; ``rho = R / R(0)``.
    """
    x = np.reshape(x, (-1, np.shape(x)[-1]))
    n = x.shape[-1]
    max_lag = min(max_lag, n - 1)
    X = scipy.fft.rfft(x, n=2 * n, axis=-1)
    r = scipy.fft.irfft(np.abs(X) ** 2, axis=-1)[:, : max_lag + 1].mean(axis=0)
    r /= n - np.arange(max_lag + 1)
    return r / r[0]


def integral_time_scale(x: np.ndarray, dt: float, max_lag_s: float,
                        method: str = "first_zero") -> float:
    """Integral time scale [s] of the ensemble autocorrelation.

    Parameters
    ----------
    method : {'first_zero', 'full'}
        'first_zero' integrates rho up to its first zero crossing (or ``max_lag_s``), right for
        a positive correlation such as u's; 'full' integrates to ``max_lag_s`` through the
        negative lobe of the transverse (v, w) correlation, whose integral is the convention's
        L / 2 (8785C) only in full.
    """
    rho = autocorrelation(x, int(round(max_lag_s / dt)))
    if method == "first_zero":
        neg = np.flatnonzero(rho <= 0.0)
        if neg.size:
            k = neg[0]
            tail = rho[k - 1] / (rho[k - 1] - rho[k])  # linear interpolation to the crossing
            return float(dt * (_trapz(rho[:k]) + 0.5 * rho[k - 1] * tail))
    elif method != "full":
        raise ValueError(f"method must be 'first_zero' or 'full', got {method!r}")
    return float(dt * _trapz(rho))


def fitted_length_scale(x: np.ndarray, dt: float, U: float, comp: int, model: str,
                        L_guess: float, max_lag_s: float) -> float:
    """Integral length scale [m] from a least-squares fit of the model correlation shape.

    Notes
    -----
    Fits L (8785C convention) in rho(U tau; L) of :func:`aerostat_gym.wind.spectra.correlation`
    to the ensemble autocorrelation for 0 <= tau <= ``max_lag_s`` and returns the implied
    integral scale, L (u) or L / 2 (v, w). Much less noisy than integrating a noisy tail, it
    tests the scale, while the PSD test checks the shape.
    """
    rho = autocorrelation(x, int(round(max_lag_s / dt)))
    xi = U * dt * np.arange(rho.size)

    def cost(logL: float) -> float:
        return float(np.sum((rho - correlation(xi, np.exp(logL), comp, model)) ** 2))

    g = np.log(L_guess)
    res = scipy.optimize.minimize_scalar(cost, bounds=(g - 3.0, g + 3.0), method="bounded",
                                         options={"xatol": 1e-6})
    L = float(np.exp(res.x))
    return L if comp == 0 else 0.5 * L


def ensemble_coherence(x: np.ndarray, y: np.ndarray, dt: float, nperseg: int | None = None,
                       edges: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Coherence |<X Y*>| / sqrt(<|X|^2> <|Y|^2>), <> over the ensemble and Welch segments.

    Parameters
    ----------
    x, y : ndarray
        Records along the last axis; leading axes are ensemble axes.
    nperseg : int, optional
        Welch segment length (Hann window, 50 % overlap); default the whole record.
    edges : ndarray, optional
        Frequency band edges [Hz]: the spectra are also summed over the bins of each band
        (more averages at high frequency); the band centres are returned instead of the bins.

    Notes
    -----
    Averaging the cross-spectrum before taking its magnitude removes the upward bias of
    single-record coherence (about 1 / sqrt(n_averages) where the true coherence is zero).
    With bands, the expectation is the PSD-weighted band mean of the coherence.
    """
    x = np.reshape(x, (-1, np.shape(x)[-1]))
    y = np.reshape(y, (-1, np.shape(y)[-1]))
    nperseg = min(nperseg or x.shape[-1], x.shape[-1])
    kw = {"fs": 1.0 / dt, "nperseg": nperseg, "detrend": False, "axis": -1}
    f, Pxy = scipy.signal.csd(x, y, **kw)
    _, Pxx = scipy.signal.welch(x, **kw)
    _, Pyy = scipy.signal.welch(y, **kw)
    spectra = [Pxy.mean(0), Pxx.mean(0), Pyy.mean(0)]
    if edges is not None:
        f, spectra = band_sums(f, spectra, edges)
    return f, np.abs(spectra[0]) / np.sqrt(spectra[1] * spectra[2])


def log_band_edges(df: float, f_hi: float, per_decade: int = 6, min_bins: int = 1) -> np.ndarray:
    """Band edges from df/2 to f_hi [Hz]: log-spaced (``per_decade``), but >= ``min_bins`` bins wide.

    The bands are therefore linear (min_bins x df wide) at low frequency and logarithmic above.
    """
    ratio = 10.0 ** (1.0 / per_decade)
    edges = [0.5 * df]
    while edges[-1] < f_hi:
        edges.append(min(max(edges[-1] + min_bins * df, edges[-1] * ratio), f_hi))
        if f_hi - edges[-1] < min_bins * df:
            edges[-1] = f_hi
    return np.array(edges)


def band_sums(f: np.ndarray, arrays: list[np.ndarray], edges: np.ndarray):
    """Sum each array over the frequency bins of each band [edges[i], edges[i+1]); empty bands dropped."""
    idx = np.searchsorted(edges, f, side="right") - 1
    keep = [i for i in range(len(edges) - 1) if np.any(idx == i)]
    centres = np.array([np.sqrt(edges[i] * edges[i + 1]) if edges[i] > 0 else edges[i + 1] / 2
                        for i in keep])
    return centres, [np.array([a[idx == i].sum() for i in keep]) for a in arrays]


def target_psd(cfg: TurbulenceConfig, U: float, comp: int, f: np.ndarray) -> np.ndarray:
    """Analytic one-sided PSD of component ``comp`` seen at a point in wind U [(m/s)^2/Hz]."""
    L = cfg.scales_8785c()[comp]
    return temporal_psd(f, U, cfg.sigmas[comp], L, comp, cfg.model)


def target_coherence(cfg: TurbulenceConfig, U: float, comp: int, f, r):
    """IEC coherence target of ``cfg`` for component ``comp`` at separation r [m]."""
    return iec_coherence(f, r, U, cfg.coherence_decay, cfg.coherence_lengths()[comp])


def row_of(wp: np.ndarray, height: float) -> int:
    """Index of the field row nearest to ``height`` [m]."""
    return int(round((height - wp[W_FIELD_Z0]) / wp[W_FIELD_DZ]))


def realised_statistics(cfg: TurbulenceConfig, wp: np.ndarray, fields: list[np.ndarray],
                        separations=(10.0, 20.0, 50.0), freqs=(0.01, 0.03, 0.1)) -> dict:
    """Realised sigma, integral length scale and coherence of generated fields vs their targets.

    ``fields`` is a list of fields from :func:`aerostat_gym.wind.build_wind` with the same
    ``wp`` grids (one per seed). Statistics are taken at the field row nearest
    ``cfg.reference_height`` and, for coherence, against the rows ``separations`` [m] below it,
    averaged over a band of +-30 % around each of ``freqs`` [Hz]. A single 600 s record gives
    only rough values (sigma^2 is uncertain by about sqrt(2 T_int / T) ~ 35 % for u).
    """
    dt, U = wp[W_FIELD_DT], wp[W_TAYLOR_U]
    wf = np.stack(fields)  # (seeds, nz, nt, 3)
    k0 = row_of(wp, cfg.reference_height) if wf.shape[1] > 1 else 0
    out = {"height": float(wp[W_FIELD_Z0] + k0 * wp[W_FIELD_DZ]), "advection_speed": float(U),
           "seeds": len(fields), "record_s": float(wf.shape[2] * dt), "components": {}}
    for c, name in enumerate(COMPONENTS):
        x = wf[..., c]
        out["components"][name] = {
            **_sigma_and_scale(cfg, x[:, k0], dt, U, c),
            "coherence": {f"{r:g}": _coherence_at(cfg, x, k0, r, dt, U, c, freqs)
                          for r in separations},
        }
    return out


def _sigma_and_scale(cfg: TurbulenceConfig, x: np.ndarray, dt: float, U: float, c: int) -> dict:
    """sigma, fitted and model-free integral length scales of records x (seeds, nt)."""
    target = cfg.integral_scales()[c]
    method = "first_zero" if c == 0 else "full"
    acf = U * integral_time_scale(x, dt, 8.0 * target / U, method)
    fit = fitted_length_scale(x, dt, U, c, cfg.model, cfg.scales_8785c()[c], 4.0 * target / U)
    return {"sigma": float(np.sqrt(mean_square(x))), "sigma_target": cfg.sigmas[c],
            "integral_length": fit, "integral_length_acf": float(acf),
            "integral_length_acf_method": method, "integral_length_target": target}


def _coherence_at(cfg, x, k0, r, dt, U, c, freqs) -> dict:
    """Band-averaged ensemble coherence between row k0 and the row r metres below it."""
    want = []
    got = []
    nz = x.shape[1]
    k1 = k0 - int(round(r / cfg.dz))
    for f0 in freqs:
        edges = np.array([f0 / 1.3, f0 * 1.3])
        fb, P = welch_psd(x[:, k0], dt, nperseg=min(x.shape[-1], 2048))
        S, T = target_psd(cfg, U, c, fb), target_coherence(cfg, U, c, fb, r)
        _, (num, den) = band_sums(fb, [S * T, S], edges)
        if num.size == 0:  # the record is too short to resolve this band: nothing to compare
            want.append(float("nan"))
            got.append(float("nan"))
            continue
        want.append(float(num[0] / den[0]))
        if nz == 1:  # single-point (filter) field: the same series at every height
            got.append(1.0)
        elif k1 < 0:
            got.append(float("nan"))
        else:
            _, C = ensemble_coherence(x[:, k0], x[:, k1], dt, min(x.shape[-1], 2048), edges)
            got.append(float(C[0]))
    return {"freq_hz": list(freqs), "realised": got, "target": want}


def _trapz(y: np.ndarray) -> float:
    """Trapezoid-rule integral of unit-spaced samples."""
    return float(y.sum() - 0.5 * (y[0] + y[-1])) if y.size > 1 else 0.0
