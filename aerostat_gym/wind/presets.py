"""Turbulence configuration and the named intensity classes ``none``, ``light``, ``moderate``,
``severe``.

The classes are wind-scaled: sigma_u, sigma_v, sigma_w follow from each episode's mean wind at
the aerostat's height h (``reference_height``, 300 m) through a cited model
(``intensity_model``), so the turbulence intensity, not sigma, is what a class fixes:

- ``"mil"`` (default): MIL-F-8785C / MIL-HDBK-1797 low-altitude model, h in ft:
  sigma_w = 0.1 W20 f, sigma_u = sigma_v = sigma_w / (0.177 + 0.000823 h)^0.4, L_u = 2 L_v =
  h / (0.177 + 0.000823 h)^1.2, L_w = h / 2 (1797 convention), with W20 the configured mean
  profile's own speed at 20 ft (6.096 m) and f the class factor below.
- ``"neutral"``: neutral atmospheric boundary layer (ESDU 85020 family, Counihan; Panofsky &
  Dutton): sigma_u = 2.5 u* f, sigma_v = 2.0 u* f, sigma_w = 1.25 u* f with
  u* = kappa U(h) / ln(h / z0), kappa = 0.4, z0 the profile's roughness length; intensity
  sigma_u / U(h) = f / ln(h / z0), whatever the wind speed. Length scales: the config's L_u, L_v, L_w.
- ``"iec"``: IEC 61400-1 Ed. 3 normal turbulence model, sigma_u = I_ref (0.75 U(h) + 5.6) m/s,
  sigma_v = 0.8 sigma_u, sigma_w = 0.5 sigma_u (Kaimal, Annex B), I_ref = 0.12 / 0.14 / 0.16
  (classes C / B / A) for light / moderate / severe; Kaimal integral scales 340.2 / 113.4 /
  27.72 m. A 90th-percentile design value for hub heights near 100 m: harsher than typical.
- ``"fixed"``: the explicit ``sigma_u``, ``sigma_v``, ``sigma_w`` (for a measured site).

Class factor f: light 0.5, moderate 1, severe 1.5, the ratios of MIL-F-8785C's severity winds
(W20 = 15 / 30 / 45 kt). Turbulence intensity sigma_u / U(h) at h = 300 m for the baseline
(uniform profile, z0 = 0.05 m):

==========  ===========  ===============  =========================  ============================
class       mil          neutral          iec (4 / 8 / 16 m/s)       source band
==========  ===========  ===============  =========================  ============================
none        0            0                0                          mean wind only ([LN02])
light       5.0 %        5.7 %            25.8 / 17.4 / 13.2 %       stable: < 5-6 % (notes)
moderate    10.1 %       11.5 %           30.1 / 20.3 / 15.4 %       neutral 1/ln(h/z0): 9.7-12.5 %
severe      15.1 %       17.2 %           34.4 / 23.2 / 17.6 %       convective: up to 2 x neutral
==========  ===========  ===============  =========================  ============================

(neutral band for z0 = 0.01-0.1 m; with a log profile over z0 = 0.05 m the MIL W20 drops to
0.55 U(300 m) and its intensities to 2.8 / 5.5 / 8.3 %.) Scaling one frozen unit-variance
field by these sigmas is exact: none of the three models' spectral shapes (length scales,
coherence) depends on the wind speed, only on the height, and the spatial field is the same
for every U (Taylor), so the environment keeps a bank of unit fields and scales them per
episode (:func:`TurbulenceConfig.for_wind`).

Coherence: IEC 61400-1 Ed.3 exponential model, a = 12, L_c = 340 m for u (above 60 m), v and w
with L_c scaled by 2.7/8.1 and 0.66/8.1 (pyconturb 'iec3d').
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field, fields

from ..checks import is_finite_number
from ..physics.wind import MIN_ADVECTION_SPEED, W_Z0, mean_speed
from .spectra import (
    CONVENTIONS,
    FT,
    KT,
    MODELS,
    W20_KT,
    integral_scale,
    mil_low_altitude,
    to_8785c,
)

METHODS = ("spectral", "filter")
INTENSITY_MODELS = ("fixed", "mil", "neutral", "iec")
INTENSITY_CLASSES = ("none", "light", "moderate", "severe")
#: class factor on the model's sigma: MIL-F-8785C severity winds 15 / 30 / 45 kt, over 30 kt
CLASS_FACTOR = {"none": 0.0, "light": 0.5, "moderate": 1.0, "severe": 1.5}
#: IEC 61400-1 Ed. 3 reference intensities I_ref of classes C / B / A
IEC_IREF = {"none": 0.0, "light": 0.12, "moderate": 0.14, "severe": 0.16}
IEC_SCALES = (340.2, 113.4, 27.72)  # [m] Kaimal integral scales 8.1, 2.7, 0.66 x 42 m (IEC Annex B)
KARMAN = 0.4  # von Karman constant
NEUTRAL_RATIOS = (2.5, 2.0, 1.25)  # sigma_u, sigma_v, sigma_w over u* (neutral surface layer)
W20_HEIGHT = 20.0 * FT  # [m] the MIL model's reference wind height, 20 ft


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
    intensity_model: str = _f("-", "SOURCED", "how sigma follows the mean wind: 'fixed' (the "
                              "sigma_* fields), 'mil' (MIL-F-8785C low altitude, W20 from the "
                              "mean profile), 'neutral' (boundary layer, sigma_u = 2.5 u*) or "
                              "'iec' (IEC 61400-1 normal turbulence model)", "fixed")
    intensity: str = _f("-", "SOURCED", "intensity class of a wind-scaled model: none, light, "
                        "moderate or severe (MIL severity ratios 15 / 30 / 45 kt; IEC C / B / A)",
                        "moderate")

    def __post_init__(self) -> None:
        _check_choice("model", self.model, MODELS)
        _check_choice("method", self.method, METHODS)
        _check_choice("convention", self.convention, CONVENTIONS)
        _check_choice("intensity_model", self.intensity_model, INTENSITY_MODELS)
        _check_choice("intensity", self.intensity, INTENSITY_CLASSES)
        if self.intensity_model != "fixed" and any(self.sigmas):
            raise ValueError("explicit turbulence sigma_u / sigma_v / sigma_w need intensity_model "
                             f"'fixed', got intensity_model {self.intensity_model!r}")
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
        """True when all intensities are zero or the class is 'none' (no field is generated)."""
        if self.intensity_model == "fixed":
            return not any(self.sigmas)
        return self.intensity == "none"

    @property
    def wind_scaled(self) -> bool:
        """True when sigma follows the mean wind (any intensity model but 'fixed')."""
        return self.intensity_model != "fixed"

    def model_sigmas(self, speed: float, w20: float, z0: float) -> tuple[float, float, float]:
        """(sigma_u, sigma_v, sigma_w) [m/s] of the intensity model.

        Parameters
        ----------
        speed : float
            Mean wind speed U(h) at ``reference_height`` [m/s].
        w20 : float
            Mean wind speed at 20 ft (6.096 m) [m/s] (the MIL model's W20).
        z0 : float
            Roughness length [m] (the neutral model's u* = kappa U(h) / ln(h / z0)).
        """
        for name, v in (("speed", speed), ("w20", w20)):
            if not (math.isfinite(v) and v >= 0):
                raise ValueError(f"turbulence {name} must be finite and >= 0 [m/s], got {v!r}")
        if self.intensity_model == "fixed":
            return self.sigmas
        f = CLASS_FACTOR[self.intensity]
        h = self.reference_height
        if self.intensity_model == "mil":
            mil = mil_low_altitude(h, w20)
            return (f * mil["sigma_u"], f * mil["sigma_v"], f * mil["sigma_w"])
        if self.intensity_model == "neutral":
            if not (math.isfinite(z0) and 0 < z0 < h):
                raise ValueError(f"the neutral turbulence model needs 0 < z0 < reference_height, "
                                 f"got z0 = {z0!r} m")
            ustar = KARMAN * speed / math.log(h / z0)
            return tuple(f * r * ustar for r in NEUTRAL_RATIOS)
        su = IEC_IREF[self.intensity] * (0.75 * speed + 5.6)
        return (su, 0.8 * su, 0.5 * su)

    def model_scales(self) -> tuple[float, float, float]:
        """(L_u, L_v, L_w) [m] in the config's ``convention``: the MIL low-altitude scales at
        ``reference_height`` for 'mil', the Kaimal integral scales for 'iec', else the
        config's own L_u, L_v, L_w."""
        if self.intensity_model == "mil":
            mil = mil_low_altitude(self.reference_height, 0.0, self.model, self.convention)
            return (mil["L_u"], mil["L_v"], mil["L_w"])
        if self.intensity_model == "iec":
            return tuple(L if self.convention == "1797" or k == 0 else 2.0 * L
                         for k, L in enumerate(IEC_SCALES))
        return (self.L_u, self.L_v, self.L_w)

    def for_wind(self, wp) -> TurbulenceConfig:
        """The explicit ('fixed') config of this class in the mean wind ``wp``.

        ``wp`` is a packed mean-wind vector (:func:`aerostat_gym.physics.wind.pack_wind`);
        U(h) is its speed at ``reference_height``, W20 its speed at 20 ft and z0 its roughness
        length. A 'fixed' config is returned unchanged.
        """
        if not self.wind_scaled:
            return self
        speed = float(mean_speed(self.reference_height, wp))
        w20 = float(mean_speed(W20_HEIGHT, wp))
        su, sv, sw = self.model_sigmas(speed, w20, float(wp[W_Z0]))
        L_u, L_v, L_w = self.model_scales()
        return self.replace(intensity_model="fixed", sigma_u=su, sigma_v=sv, sigma_w=sw,
                            L_u=L_u, L_v=L_v, L_w=L_w)

    def unit(self) -> TurbulenceConfig:
        """The explicit config with unit sigmas and this class's length scales: the frozen
        field the environment scales per episode by :meth:`for_wind`'s sigmas (exact, since no
        model's spectral shape depends on the wind speed)."""
        L_u, L_v, L_w = self.model_scales()
        return self.replace(intensity_model="fixed", sigma_u=1.0, sigma_v=1.0, sigma_w=1.0,
                            L_u=L_u, L_v=L_v, L_w=L_w)

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
        """Copy with fields replaced (validated again). Explicit sigma_* without an
        ``intensity_model`` make the copy 'fixed' (a measured site's values)."""
        return dataclasses.replace(self, **_explicit_sigmas(changes))

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
    if not (is_finite_number(value) and (value >= 0 if allow_zero else value > 0)):
        need = ">= 0" if allow_zero else "> 0"
        raise ValueError(f"turbulence {name} must be a finite number {need}, got {value!r}")


PRESETS: dict[str, TurbulenceConfig] = {
    "none": TurbulenceConfig(),
    **{name: TurbulenceConfig(intensity_model="mil", intensity=name)
       for name in ("light", "moderate", "severe")},
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


def _explicit_sigmas(changes: dict) -> dict:
    """``changes`` with intensity_model 'fixed' added when it sets a sigma but no model."""
    if any(k in changes for k in ("sigma_u", "sigma_v", "sigma_w")) and \
            "intensity_model" not in changes:
        return {**changes, "intensity_model": "fixed"}
    return changes


def describe(cfg: TurbulenceConfig) -> list[dict]:
    """Rows (name, value, unit, status, doc) for every field of ``cfg``."""
    return [{"name": f.name, "value": getattr(cfg, f.name), **f.metadata} for f in fields(cfg)]
