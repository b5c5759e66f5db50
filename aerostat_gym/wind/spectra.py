"""Analytic turbulence spectra and the MIL-F-8785C low-altitude parameter tables.

Conventions (read once, they bite):

- Spectra Phi(Omega) are spatial, one-sided, in (m/s)^2 per (rad/m), with
  integral over Omega in (0, inf) = sigma^2.
- A frozen field advected past a fixed point at speed V gives the one-sided temporal PSD in Hz
  ``S(f) = 2 pi Phi(2 pi f / V) / V`` (what ``scipy.signal.welch`` estimates).
- Length scales are stored either in the MIL-F-8785C convention, where the lateral and vertical
  spectra use L (their integral scale is L / 2), or in the MIL-HDBK-1797 convention, where they
  use 2 L with halved L (L is then itself the integral scale). Both describe the same spectra;
  internally everything is converted to 8785C (:func:`to_8785c`). L_u is the same in both.
- Component index: 0 = u (along the mean wind, longitudinal spectrum), 1 = v (lateral),
  2 = w (vertical); v and w use the transverse spectrum.

References: MIL-F-8785C (1980) and MIL-HDBK-1797 (1997) forms as given by the MathWorks
Aerospace Blockset Dryden / von Karman blocks; low-altitude tables as in JSBSim ``FGWinds.cpp``.
"""

from __future__ import annotations

import math

import numpy as np
import scipy.special

FT = 0.3048  # metres per foot
KT = 0.514444  # m/s per knot
VK_A = 1.339  # von Karman scale factor a in Phi_u ~ (1 + (a L Omega)^2)^(-5/6)
CONVENTIONS = ("8785C", "1797")
MODELS = ("dryden", "von_karman")
# MIL severity levels as wind speed at 20 ft (MathWorks low-altitude model): light/moderate/severe
W20_KT = {"light": 15.0, "moderate": 30.0, "severe": 45.0}


def to_8785c(L: float, comp: int, convention: str) -> float:
    """Length scale in the 8785C convention from one given in ``convention`` [m]."""
    if convention not in CONVENTIONS:
        raise ValueError(f"unknown length-scale convention {convention!r}; use one of {CONVENTIONS}")
    return 2.0 * L if (convention == "1797" and comp != 0) else L


def integral_scale(L: float, comp: int, convention: str) -> float:
    """Integral length scale (integral of the autocorrelation over separation) [m].

    Notes
    -----
    ``L_int = (pi / 2) Phi(0) / sigma^2``: L for u in both conventions; L / 2 for v, w in 8785C,
    L for v, w in 1797.
    """
    L8 = to_8785c(L, comp, convention)
    return L8 if comp == 0 else 0.5 * L8


def phi_dryden(omega, sigma: float, L: float, comp: int):
    """Dryden spatial PSD (MIL-F-8785C form) [(m/s)^2 / (rad/m)].

    Notes
    -----
    ``Phi_u = sigma^2 (2 L / pi) / (1 + (L Omega)^2)``;
    ``Phi_{v,w} = sigma^2 (L / pi) (1 + 3 (L Omega)^2) / (1 + (L Omega)^2)^2``.
    High-frequency slope -2.
    """
    x2 = (L * np.asarray(omega, dtype=float)) ** 2
    if comp == 0:
        return sigma**2 * (2.0 * L / math.pi) / (1.0 + x2)
    return sigma**2 * (L / math.pi) * (1.0 + 3.0 * x2) / (1.0 + x2) ** 2


def phi_von_karman(omega, sigma: float, L: float, comp: int):
    """Von Karman spatial PSD (MIL-F-8785C form) [(m/s)^2 / (rad/m)].

    Notes
    -----
    With a = 1.339: ``Phi_u = sigma^2 (2 L / pi) / (1 + (a L Omega)^2)^(5/6)``;
    ``Phi_{v,w} = sigma^2 (L / pi) (1 + (8/3)(a L Omega)^2) / (1 + (a L Omega)^2)^(11/6)``.
    High-frequency slope -5/3 (Kolmogorov inertial range).
    """
    x2 = (VK_A * L * np.asarray(omega, dtype=float)) ** 2
    if comp == 0:
        return sigma**2 * (2.0 * L / math.pi) / (1.0 + x2) ** (5.0 / 6.0)
    return sigma**2 * (L / math.pi) * (1.0 + (8.0 / 3.0) * x2) / (1.0 + x2) ** (11.0 / 6.0)


def spatial_psd(omega, sigma: float, L: float, comp: int, model: str):
    """Spatial PSD of ``model`` ('dryden' or 'von_karman'), L in the 8785C convention."""
    if model == "dryden":
        return phi_dryden(omega, sigma, L, comp)
    if model == "von_karman":
        return phi_von_karman(omega, sigma, L, comp)
    raise ValueError(f"unknown turbulence model {model!r}; use one of {MODELS}")


def temporal_psd(f, V: float, sigma: float, L: float, comp: int, model: str):
    """One-sided temporal PSD in Hz seen at a fixed point, S(f) = 2 pi Phi(2 pi f / V) / V."""
    f = np.asarray(f, dtype=float)
    return 2.0 * math.pi * spatial_psd(2.0 * math.pi * f / V, sigma, L, comp, model) / V


def mil_low_altitude(height: float, w20: float, model: str = "dryden",
                     convention: str = "8785C") -> dict:
    """MIL-F-8785C intensities and scale lengths at ``height`` [m] for wind ``w20`` [m/s] at 20 ft.

    Returns a dict with sigma_u, sigma_v, sigma_w [m/s] and L_u, L_v, L_w [m] in ``convention``.

    Notes
    -----
    Low altitude (h < 1000 ft, h in ft, clipped at >= 10 ft as JSBSim does):
    ``L_w = h``, ``L_u = L_v = h / (0.177 + 0.000823 h)^1.2``; ``sigma_w = 0.1 W20``,
    ``sigma_u = sigma_v = sigma_w / (0.177 + 0.000823 h)^0.4``. Between 1000 and 2000 ft the
    scales go linearly to the isotropic high-altitude value (1750 ft Dryden, 2500 ft von
    Karman) and stay there above. The intensities are held at their 1000 ft value above
    1000 ft: the high-altitude probability-of-exceedance table is not reproduced here.
    """
    if not (math.isfinite(height) and height >= 0 and math.isfinite(w20) and w20 >= 0):
        raise ValueError(f"height and w20 must be finite and >= 0, got {height!r}, {w20!r}")
    if model not in MODELS:
        raise ValueError(f"unknown turbulence model {model!r}; use one of {MODELS}")
    h = max(height / FT, 10.0)
    lu, lw = _mil_scales_ft(h, model)
    c = 0.177 + 0.000823 * min(h, 1000.0)
    sw = 0.1 * w20
    su = sw / c**0.4
    L = {"L_u": lu * FT, "L_v": lu * FT, "L_w": lw * FT}
    if convention == "1797":
        L["L_v"], L["L_w"] = 0.5 * L["L_v"], 0.5 * L["L_w"]
    elif convention != "8785C":
        raise ValueError(f"unknown length-scale convention {convention!r}; use one of {CONVENTIONS}")
    return {"sigma_u": su, "sigma_v": su, "sigma_w": sw, **L}


def _mil_scales_ft(h: float, model: str) -> tuple[float, float]:
    """8785C (L_u = L_v, L_w) in feet at height h [ft]: low, transition and high altitude."""
    high = {"dryden": 1750.0, "von_karman": 2500.0}[model]
    if h <= 1000.0:
        return h / (0.177 + 0.000823 * h) ** 1.2, h
    lu0, lw0 = _mil_scales_ft(1000.0, model)
    s = min((h - 1000.0) / 1000.0, 1.0)
    return lu0 + s * (high - lu0), lw0 + s * (high - lw0)


def correlation(xi, L: float, comp: int, model: str):
    """Spatial autocorrelation rho(xi) along the wind, L in the 8785C convention.

    Notes
    -----
    Dryden: ``rho_u = exp(-xi / L)``, ``rho_{v,w} = exp(-xi / L) (1 - xi / (2 L))``.
    Von Karman, with zeta = xi / (1.339 L) and c = 2^(2/3) / Gamma(1/3):
    ``rho_u = c zeta^(1/3) K_{1/3}(zeta)``,
    ``rho_{v,w} = c zeta^(1/3) (K_{1/3}(zeta) - zeta K_{2/3}(zeta) / 2)``.
    Their integrals over xi in (0, inf) are L (u) and L / 2 (v, w).
    """
    xi = np.abs(np.asarray(xi, dtype=float))
    if model == "dryden":
        e = np.exp(-xi / L)
        return e if comp == 0 else e * (1.0 - xi / (2.0 * L))
    if model != "von_karman":
        raise ValueError(f"unknown turbulence model {model!r}; use one of {MODELS}")
    z = np.maximum(xi / (VK_A * L), 1e-12)
    c = 2.0 ** (2.0 / 3.0) / scipy.special.gamma(1.0 / 3.0)
    k13 = scipy.special.kv(1.0 / 3.0, z)
    if comp == 0:
        return np.minimum(c * z ** (1.0 / 3.0) * k13, 1.0)
    return np.minimum(c * z ** (1.0 / 3.0) * (k13 - 0.5 * z * scipy.special.kv(2.0 / 3.0, z)), 1.0)
