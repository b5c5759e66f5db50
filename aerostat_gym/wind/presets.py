"""Turbulence configuration and the named presets ``none``, ``light``, ``moderate``, ``severe``.

The presets follow the recommended parameter set for a 300 m tether and an 18 m aerostat at a
Penticton-like site (aerostat at h ~ 250-310 m, z0 ~ 0.05 m, nominal U(h) ~ 8 m/s):

==========  =======  =======  =======  =====  ======  ======  =============================
preset      sigma_u  sigma_v  sigma_w  L_u    L_v     L_w     meaning
==========  =======  =======  =======  =====  ======  ======  =============================
none        0        0        0        300    120     60      mean wind only (the paper)
light       0.8      0.64     0.48     300    120     60      TI 10 % at 8 m/s
moderate    1.6      1.28     0.96     300    120     60      TI 20 % at 8 m/s
severe      2.4      1.92     1.44     300    120     60      TI 30 % at 8 m/s, 16 % at 15 m/s
==========  =======  =======  =======  =====  ======  ======  =============================

(sigma in m/s, L in m, MIL-HDBK-1797 convention, so every L is the integral length scale.)
Reasoning: sigma_u is the MIL-F-8785C low-altitude rule, sigma_u = 0.1 W20 /
(0.177 + 0.000823 h[ft])^0.4, with the MIL severity winds W20 = 15 / 30 / 45 kt: 0.79 / 1.59 /
2.38 m/s at 280 m and 0.78 / 1.55 / 2.33 m/s at 300 m, rounded to 0.8 / 1.6 / 2.4. 'light' is
also the notes' nominal sigma_u ~ 0.10 U(h) for the neutral log law. sigma_v / sigma_u = 0.8
and sigma_w / sigma_u = 0.6 sit between IEC 61400-1 (0.8 / 0.5) and the nearly isotropic MIL
model at 280 m. L_u = 300 m is between MIL (304 m),
IEC (340 m), Eurocode (357 m) and Counihan (220 m); L_v = 120 m and L_w = 60 m are integral
scales where standards disagree (IEC: w 28 m; MIL: w 140 m), so randomise them in training.
Coherence: IEC 61400-1 Ed.3 exponential model, a = 12, L_c = 340 m for u (above 60 m), v and w
with L_c scaled by 2.7/8.1 and 0.66/8.1 (pyconturb 'iec3d').
"""

from __future__ import annotations

import dataclasses
import math
import numbers
from dataclasses import dataclass, field, fields

from ..physics.wind import MIN_ADVECTION_SPEED
from .spectra import CONVENTIONS, KT, MODELS, W20_KT, integral_scale, mil_low_altitude, to_8785c

METHODS = ("spectral", "filter")


def _f(unit: str, status: str, doc: str, default):
    return field(default=default, metadata={"unit": unit, "status": status, "doc": doc})


@dataclass(frozen=True)
class TurbulenceConfig:
    """Turbulence model, intensities, scales, coherence and the field grid of one episode.

    Every field carries its unit, status (SOURCED / ESTIMATE) and a one-line reason in its
    metadata (``dataclasses.fields(TurbulenceConfig)[i].metadata``); see :func:`describe`.
    Invalid values (negative intensity, non-positive length scale, unknown model ...) raise
    ``ValueError`` naming the field.
    """

    model: str = _f("-", "ESTIMATE", "spectrum: 'von_karman' (f^-5/3, default) or 'dryden' (f^-2)",
                    "von_karman")
    method: str = _f("-", "ESTIMATE", "'spectral': Veers coherent multi-height field; 'filter': "
                     "exact Dryden forming filters at reference_height, applied at all heights",
                     "spectral")
    sigma_u: float = _f("m/s", "ESTIMATE", "std of u (along the mean wind)", 0.0)
    sigma_v: float = _f("m/s", "ESTIMATE", "std of v (lateral)", 0.0)
    sigma_w: float = _f("m/s", "ESTIMATE", "std of w (vertical)", 0.0)
    L_u: float = _f("m", "ESTIMATE", "u length scale (= integral scale in both conventions)", 300.0)
    L_v: float = _f("m", "ESTIMATE", "v length scale in `convention`", 120.0)
    L_w: float = _f("m", "ESTIMATE", "w length scale in `convention`", 60.0)
    convention: str = _f("-", "SOURCED", "'1797': L_v, L_w are integral scales; '8785C': integral "
                         "scale is L / 2 for v and w (MIL-HDBK-1797 vs MIL-F-8785C)", "1797")
    coherence_decay: float = _f("-", "SOURCED", "IEC coherence decay a (IEC 61400-1 Ed.3)", 12.0)
    coherence_length_u: float = _f("m", "SOURCED", "IEC coherence length L_c of u (8.1 x 42 m)",
                                   340.2)
    coherence_length_v: float = _f("m", "SOURCED", "L_c of v (L_c x 2.7/8.1, pyconturb iec3d)", 113.4)
    coherence_length_w: float = _f("m", "SOURCED", "L_c of w (L_c x 0.66/8.1, pyconturb iec3d)", 27.72)
    reference_height: float = _f("m", "ESTIMATE", "aerostat nominal height (baseline trim at 8 m/s: "
                                 "CM at ~312 m, confluence point ~300 m): U_a = U(this) advects the "
                                 "frozen field and converts spatial to temporal spectra", 300.0)
    z_min: float = _f("m", "ESTIMATE", "lowest field height (the winch)", 0.0)
    z_max: float = _f("m", "ESTIMATE", "highest field height (above the top fin, ~318 m, of the "
                      "baseline 300 m tether; higher points read the top row)", 340.0)
    dz: float = _f("m", "ESTIMATE", "field height step, about the hull diameter (interpolation "
                   "between rows smooths like the hull's own spatial averaging)", 5.0)
    dt: float = _f("s", "ESTIMATE", "field time step (pitch/yaw modes <= 0.5 Hz; notes: 0.1-0.2 s)",
                   0.1)
    downwind_extent: float = _f("m", "ESTIMATE", "farthest downwind point the field serves "
                                "(longest tether, 400 m)", 400.0)
    upwind_extent: float = _f("m", "ESTIMATE", "farthest upwind point the field serves", 50.0)
    min_advection_speed: float = _f("m/s", "ESTIMATE", "floor of U_a (Taylor fails below 1-2 m/s)",
                                    MIN_ADVECTION_SPEED)

    def __post_init__(self) -> None:
        _check_choice("model", self.model, MODELS)
        _check_choice("method", self.method, METHODS)
        _check_choice("convention", self.convention, CONVENTIONS)
        if self.method == "filter" and self.model != "dryden":
            raise ValueError("turbulence method 'filter' (exact forming filters) needs model "
                             f"'dryden', got model {self.model!r}")
        for name in ("sigma_u", "sigma_v", "sigma_w", "coherence_decay", "z_min",
                     "downwind_extent", "upwind_extent"):
            _check_number(name, getattr(self, name), allow_zero=True)
        for name in ("L_u", "L_v", "L_w", "coherence_length_u", "coherence_length_v",
                     "coherence_length_w", "dz", "dt", "min_advection_speed", "reference_height"):
            _check_number(name, getattr(self, name), allow_zero=False)
        if not self.z_min < self.z_max:
            raise ValueError(f"turbulence z_max ({self.z_max!r} m) must exceed z_min ({self.z_min!r} m)")
        if not self.z_min <= self.reference_height <= self.z_max:
            raise ValueError(f"turbulence reference_height {self.reference_height!r} m must lie in "
                             f"the field heights [{self.z_min!r}, {self.z_max!r}] m")

    @property
    def sigmas(self) -> tuple[float, float, float]:
        """(sigma_u, sigma_v, sigma_w) [m/s]."""
        return (self.sigma_u, self.sigma_v, self.sigma_w)

    @property
    def is_off(self) -> bool:
        """True when all intensities are zero (no field is generated)."""
        return not any(self.sigmas)

    def scales_8785c(self) -> tuple[float, float, float]:
        """Length scales converted to the MIL-F-8785C convention used by the spectra [m]."""
        Ls = (self.L_u, self.L_v, self.L_w)
        return tuple(to_8785c(L, k, self.convention) for k, L in enumerate(Ls))

    def integral_scales(self) -> tuple[float, float, float]:
        """Target integral length scales of u, v, w [m]."""
        Ls = (self.L_u, self.L_v, self.L_w)
        return tuple(integral_scale(L, k, self.convention) for k, L in enumerate(Ls))

    def coherence_lengths(self) -> tuple[float, float, float]:
        """IEC coherence lengths L_c of u, v, w [m]."""
        return (self.coherence_length_u, self.coherence_length_v, self.coherence_length_w)

    def heights(self) -> tuple[float, float, int]:
        """(z0, dz, n) of the field's height grid; the last row is at or above z_max."""
        n = int(math.ceil((self.z_max - self.z_min) / self.dz - 1e-9)) + 1
        return self.z_min, self.dz, n

    def replace(self, **changes) -> TurbulenceConfig:
        """Copy with fields replaced (validated again)."""
        return dataclasses.replace(self, **changes)

    @classmethod
    def from_mil(cls, severity: str | float, height: float = 300.0, model: str = "von_karman",
                 convention: str = "1797", **changes) -> TurbulenceConfig:
        """Intensities and length scales from the MIL-F-8785C low-altitude model at ``height``.

        ``severity`` is 'light', 'moderate', 'severe' (W20 = 15, 30, 45 kt) or W20 itself [m/s].
        """
        if isinstance(severity, str):
            _check_choice("severity", severity, tuple(W20_KT))
            severity = W20_KT[severity] * KT
        mil = mil_low_altitude(height, float(severity), model, convention)
        return cls(model=model, convention=convention, reference_height=height,
                   **{**mil, **changes})


def _check_choice(name: str, value, choices) -> None:
    if value not in choices:
        raise ValueError(f"turbulence {name} must be one of {list(choices)}, got {value!r}")


def _check_number(name: str, value, allow_zero: bool) -> None:
    ok = isinstance(value, numbers.Real) and not isinstance(value, bool) and math.isfinite(value)
    ok = ok and (value >= 0 if allow_zero else value > 0)
    if not ok:
        need = ">= 0" if allow_zero else "> 0"
        raise ValueError(f"turbulence {name} must be a finite number {need}, got {value!r}")


def _preset(sigma_u: float) -> TurbulenceConfig:
    """Preset with the notes' anisotropy sigma_v = 0.8 sigma_u, sigma_w = 0.6 sigma_u."""
    return TurbulenceConfig(sigma_u=sigma_u, sigma_v=round(0.8 * sigma_u, 6),
                            sigma_w=round(0.6 * sigma_u, 6))


PRESETS: dict[str, TurbulenceConfig] = {
    "none": _preset(0.0),
    "light": _preset(0.8),
    "moderate": _preset(1.6),
    "severe": _preset(2.4),
}


def get_preset(name: str) -> TurbulenceConfig:
    """The named preset; an unknown name is a ``ValueError`` listing the valid ones."""
    if name not in PRESETS:
        raise ValueError(f"unknown turbulence preset {name!r}; choose one of {list(PRESETS)}")
    return PRESETS[name]


def resolve_turbulence(turbulence) -> TurbulenceConfig:
    """A :class:`TurbulenceConfig` from a preset name, a config, a dict of fields or None."""
    if turbulence is None:
        return PRESETS["none"]
    if isinstance(turbulence, TurbulenceConfig):
        return turbulence
    if isinstance(turbulence, str):
        return get_preset(turbulence)
    if isinstance(turbulence, dict):
        return _from_dict(turbulence)
    raise TypeError(f"turbulence must be a preset name, TurbulenceConfig, dict or None, "
                    f"got {type(turbulence).__name__}")


def _from_dict(d: dict) -> TurbulenceConfig:
    """Config from a dict; key 'preset' picks the base, other keys override its fields."""
    d = dict(d)
    base = get_preset(d.pop("preset", "none"))
    known = {f.name for f in fields(TurbulenceConfig)}
    unknown = sorted(set(d) - known)
    if unknown:
        raise ValueError(f"unknown turbulence field(s) {unknown}; known: {sorted(known)}")
    return base.replace(**d)


def describe(cfg: TurbulenceConfig) -> list[dict]:
    """Rows (name, value, unit, status, doc) for every field of ``cfg``."""
    return [{"name": f.name, "value": getattr(cfg, f.name), **f.metadata} for f in fields(cfg)]
