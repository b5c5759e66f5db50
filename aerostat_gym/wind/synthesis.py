"""Spectral synthesis of a coherent multi-height turbulence field (Veers method, IEC coherence).

At each frequency f_k the Veers method draws correlated Fourier coefficients for all heights
with cross-spectral matrix S_ij(f_k) = sqrt(S_i S_j) Coh_ij(f_k), factorised by Cholesky, and
an inverse real FFT gives the time series. With the IEC exponential coherence on a uniform
height grid this factorisation is closed form, which makes the field cheap enough to draw per
episode with dozens of heights (see :func:`coherent_coefficients`).

The field is homogeneous: every height has the same spectrum, converted from the spatial one
with a single advection speed U_a (the mean speed at the aerostat's nominal height), which
also sets the Taylor delay in :func:`aerostat_gym.physics.wind.air_velocity`.
"""

from __future__ import annotations

import math

import numpy as np
import scipy.fft
from numba import njit

from .spectra import temporal_psd

#: [bytes] the most memory turbulence fields may take at once (the environment's bank, or one
#: field of the simulator): float64 u, v, w at every height and sample. The default bank takes
#: 78 MiB (8 fields of 88 heights x 4,640 samples) and one at 100 m/s on a 1 km tether under
#: 1 GiB; a grid past a few GiB is a typo (dz in km, an extent in mm) that NumPy would only
#: refuse after minutes of synthesis, and the synthesis needs about four fields more on top.
MAX_FIELD_BYTES = 4 * 2**30


def field_bytes(cfg, samples: float, count: int = 1) -> float:
    """Bytes of ``count`` float64 (u, v, w) fields of ``cfg``'s height grid (a
    TurbulenceConfig) with ``samples`` along-wind or time samples each."""
    return float(count) * cfg.heights()[2] * float(samples) * 3 * 8


def check_field_size(cfg, samples: float, count: int = 1, detail: str = "") -> None:
    """Refuse (ValueError naming dz, the heights and the memory) ``count`` fields of ``samples``
    samples that would take more than :data:`MAX_FIELD_BYTES`, before anything is allocated;
    ``detail`` says where the samples come from."""
    nbytes = field_bytes(cfg, samples, count)
    if not nbytes <= MAX_FIELD_BYTES:
        z0, dz, nz = cfg.heights()
        raise ValueError(f"{count} field(s) of {nz} heights (dz = {dz:g} m from z_min = {z0:g} "
                         f"to z_max = {cfg.z_max:g} m) x {samples:.4g} samples{detail} would "
                         f"take {nbytes / 2**30:.3g} GiB, above the {MAX_FIELD_BYTES / 2**30:g} "
                         f"GiB cap (aerostat_gym.wind.synthesis.MAX_FIELD_BYTES)")


def iec_coherence(f, r, U: float, a: float = 12.0, Lc: float = 340.2):
    """IEC 61400-1 Ed.3 exponential coherence (magnitude, not squared).

    Notes
    -----
    ``Coh(r, f) = exp(-a sqrt((f r / U)^2 + (0.12 r / L_c)^2))`` for separation r [m]
    perpendicular to the mean wind, frequency f [Hz], mean speed U [m/s]. It equals
    exp(-c(f) r) with c(f) = a sqrt((f / U)^2 + (0.12 / L_c)^2): exponential in r.
    """
    f = np.asarray(f, dtype=float)
    r = np.asarray(r, dtype=float)
    return np.exp(-a * np.sqrt((f * r / U) ** 2 + (0.12 * r / Lc) ** 2))


def bin_powers(n: int, dt: float, psd, nodes: int = 4) -> np.ndarray:
    """Variance carried by each rFFT bin of an n-sample record at step dt.

    Parameters
    ----------
    n, dt : int, float
        Record length [samples] and step [s].
    psd : callable
        One-sided PSD S(f) in (m/s)^2 / Hz, vectorised over f.
    nodes : int
        Gauss-Legendre nodes per bin.

    Returns
    -------
    ndarray, shape (n // 2 + 1,)
        P_k = integral of S over [f_k - df/2, f_k + df/2] clipped to [0, f_Nyquist], df = 1/(n dt).

    Notes
    -----
    Integrating over the bin rather than sampling S(f_k) df keeps the variance of the lowest
    bins right, where the spectrum of a 300 m scale varies within one bin; the DC bin (the
    random sample mean of a finite record) carries the variance of [0, df/2]. Sum P_k is then
    the variance resolved up to the Nyquist frequency.
    """
    df = 1.0 / (n * dt)
    fk = np.arange(n // 2 + 1) * df
    lo = np.maximum(fk - 0.5 * df, 0.0)
    hi = np.minimum(fk + 0.5 * df, 0.5 / dt)
    x, w = np.polynomial.legendre.leggauss(nodes)
    mid, half = 0.5 * (hi + lo), 0.5 * (hi - lo)
    return half * (psd(mid[:, None] + half[:, None] * x) @ w)


def neighbour_coherence(n: int, dt: float, dz: float, U: float, a: float, Lc: float) -> np.ndarray:
    """Coherence rho(f_k) = Coh(dz, f_k) between adjacent field rows for every rFFT bin."""
    fk = np.arange(n // 2 + 1) / (n * dt)
    return iec_coherence(fk, dz, U, a, Lc)


def coherent_coefficients(rho: np.ndarray, nz: int, rng: np.random.Generator) -> np.ndarray:
    """Complex Gaussian coefficients e[c, k, bin], coherent in height: E[e_i e_j*] = 2 rho^|i-j|.

    Parameters
    ----------
    rho : ndarray, shape (n_comp, n_bins)
        Coherence between adjacent rows, per component and bin.
    nz : int
        Number of rows (heights).
    rng : numpy.random.Generator
        The only source of randomness; draws one (n_comp, nz, n_bins, 2) normal block
        (real and imaginary parts).

    Notes
    -----
    For an exponential coherence on a uniform grid, Coh_ij = exp(-c |z_i - z_j|) = rho^|i-j|:
    the Kac-Murdock-Szego matrix, whose Cholesky factor is the first-order recursion
    ``e_0 = xi_0, e_k = rho e_{k-1} + sqrt(1 - rho^2) xi_k`` (the coefficients form a Markov
    chain in height). This is the Veers factorisation in O(nz) per frequency instead of
    O(nz^3). xi are complex with independent N(0, 1) real and imaginary parts (Gaussian
    amplitudes, not fixed amplitudes with random phases, so each record is a Gaussian process).
    """
    n_comp, n_bins = rho.shape
    e = rng.standard_normal((n_comp, nz, n_bins, 2)).view(np.complex128)[..., 0]
    _markov_in_height(e, rho, np.sqrt(1.0 - rho**2))
    return e


@njit(cache=True)
def _markov_in_height(e, rho, s):
    """In place: e[c, k] = rho[c] e[c, k - 1] + s[c] e[c, k] for k = 1..nz-1 (per bin)."""
    for c in range(e.shape[0]):
        for k in range(1, e.shape[1]):
            for b in range(e.shape[2]):
                e[c, k, b] = rho[c, b] * e[c, k - 1, b] + s[c, b] * e[c, k, b]


def synthesize(powers: np.ndarray, e: np.ndarray, n: int) -> np.ndarray:
    """Time series x[c, k, j] from bin powers (n_comp, n_bins) and coefficients e (n_comp, nz, n_bins).

    Notes
    -----
    With the unscaled inverse transform x_j = X_0 + 2 Re sum_k X_k exp(2 pi i j k / n)
    (+ X_{n/2} (-1)^j), interior bins take X_k = sqrt(P_k) e_k / 2 and the real DC and
    Nyquist bins X = sqrt(P) Re(e), so every bin contributes variance P_k.
    """
    amp = np.sqrt(powers) * 0.5
    amp[:, 0] *= 2.0
    real_bins = [0, -1] if n % 2 == 0 else [0]
    if n % 2 == 0:
        amp[:, -1] *= 2.0
    X = amp[:, None, :] * e
    X[..., real_bins] = X[..., real_bins].real
    return scipy.fft.irfft(X, n=n, axis=-1, norm="forward")


def veers_field(cfg, U: float, n: int, rng: np.random.Generator) -> np.ndarray:
    """Coherent u, v, w field of ``cfg`` (a TurbulenceConfig) on its height grid.

    Returns
    -------
    ndarray, shape (nz, n, 3)
        C-contiguous, the layout :func:`aerostat_gym.physics.wind.air_velocity` reads.
    """
    check_field_size(cfg, n)
    _, dz, nz = cfg.heights()
    Ls, Lcs = cfg.scales_8785c(), cfg.coherence_lengths()
    powers = np.stack([
        bin_powers(n, cfg.dt, lambda f, c=c: temporal_psd(f, U, cfg.sigmas[c], Ls[c], c, cfg.model))
        for c in range(3)])
    rho = np.stack([neighbour_coherence(n, cfg.dt, dz, U, cfg.coherence_decay, Lcs[c])
                    for c in range(3)])
    x = synthesize(powers, coherent_coefficients(rho, nz, rng), n)
    return np.ascontiguousarray(np.moveaxis(x, 0, -1))


def fft_length(samples: float) -> int:
    """Smallest fast (5-smooth) rFFT length >= samples, at least 2."""
    return max(int(scipy.fft.next_fast_len(int(math.ceil(samples)), real=True)), 2)
