"""Model parameters: frozen dataclasses per component, mirrored one to one by TOML.

The baseline case (Aeros Flightcam aerostat on a 300 m Plasma tether, [LN02]) ships as
``aerostat_gym/data/aeros_flightcam.toml``. Every field carries its unit and the status of the
baseline value (SOURCED, DERIVED, ESTIMATE, CALIB) in its dataclass metadata, so
``parameter_table()`` can tell a user which numbers are measured and which are guesses.

Loading is strict: an unknown key, a missing key or section, a wrong type or an impossible
value raises :class:`ParameterError` naming the field and the value; :func:`load_params` also
refuses values no real aerostat has (unit slips, :func:`check_plausibility`). Quantities that follow
from the inputs (buoyancy, net lift, leash x_l, EA, element mass, tether damping, added masses)
are computed in :class:`Derived`, never typed in.
"""

from __future__ import annotations

import dataclasses
import difflib
import math
import os
import warnings
from collections.abc import Mapping
from dataclasses import dataclass, field, fields
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

from .checks import is_finite_number, is_number, is_whole

try:  # Python >= 3.11
    import tomllib
except ModuleNotFoundError:  # pragma: no cover
    import tomli as tomllib  # type: ignore[no-redef]


class ParameterError(ValueError):
    """An invalid, unknown or missing parameter. The message names the field and the value."""


class ParameterWarning(UserWarning):
    """A parameter set that loads and runs but is likely to fail numerically; the message names
    the field, its value and the value advised."""


# --- field helpers -----------------------------------------------------------------------------

POSITIVE, NONNEG, ANY, INT_GE1, STALL, VEC3, COEFFS, BOOL, FRACTION, EFFICIENCY = (
    "positive", "nonneg", "any", "int>=1", "stall", "vec3", "coeffs", "bool", "fraction",
    "efficiency",
)


#: Upper bound on tether.n_elements: a sanity bound on memory and step size; the trim's cost
#: grows gently with n (its Jacobian is built by banded finite differences, see
#: aerostat_gym.analysis.trim), so this is not what limits it.
MAX_ELEMENTS = 1000


def _f(unit: str, status: str, check: str = ANY, doc: str = "", default: Any = dataclasses.MISSING,
       size: int | None = None):
    meta = {"unit": unit, "status": status, "check": check, "doc": doc, "size": size}
    if default is dataclasses.MISSING:
        return field(metadata=meta)
    if isinstance(default, (list, tuple)):
        return field(default_factory=lambda d=tuple(default): d, metadata=meta)
    return field(default=default, metadata=meta)


# --- components ----------------------------------------------------------------------------------


@dataclass(frozen=True)
class EnvironmentParams:
    rho_air: float = _f("kg/m^3", "DERIVED", POSITIVE, "air density (Table 2 fit, Option A)")
    g: float = _f("m/s^2", "ESTIMATE", POSITIVE, "gravitational acceleration")


@dataclass(frozen=True)
class AerostatParams:
    length: float = _f("m", "SOURCED", POSITIVE, "hull length")
    diameter: float = _f("m", "SOURCED", POSITIVE, "maximum hull diameter")
    volume: float = _f("m^3", "SOURCED", POSITIVE, "total (buoyant) volume")
    mass: float = _f("kg", "DERIVED", POSITIVE, "total mass incl. helium and ballonet air")
    Ixx: float = _f("kg m^2", "ESTIMATE", POSITIVE, "roll inertia about the CM")
    Iyy: float = _f("kg m^2", "ESTIMATE", POSITIVE, "pitch inertia about the CM")
    Izz: float = _f("kg m^2", "ESTIMATE", POSITIVE, "yaw inertia about the CM")
    Ixz: float = _f("kg m^2", "ESTIMATE", ANY, "product of inertia, integral of x z dm")
    cb_position: tuple = _f("m", "CALIB", VEC3, "centre of buoyancy relative to the CM (body)")
    nose_position: tuple = _f("m", "CALIB", VEC3, "nose relative to the CM (body); z = hull axis")
    leash_z: float = _f("m", "SOURCED", ANY, "confluence point height relative to the CM (1.5 D below axis)")
    trim_pitch_deg: float = _f("deg", "SOURCED", ANY, "zero-wind trim pitch (negative = nose up)")
    # Lamb's coefficients of a body of revolution lie in [0, 1]: 0.5 for a sphere, k1 -> 0 and
    # k3 -> 1 as the fineness ratio grows
    k1: float = _f("-", "ESTIMATE", FRACTION, "axial added-mass coefficient")
    k3: float = _f("-", "ESTIMATE", FRACTION, "lateral added-mass coefficient (y and z)")
    air_inertia: bool = _f("-", "ESTIMATE", BOOL, "Froude-Krylov plus added-mass force "
                           "(1 + k_i) rho V dW_i/dt of accelerating air on the hull (Morison's "
                           "inertia term, local dW/dt averaged over the hull length; an upper "
                           "bound in convected frozen turbulence, hence off in the shipped "
                           "files); zero in steady wind")

    @property
    def inertia_tensor(self) -> np.ndarray:
        """Inertia tensor about the CM in body axes [kg m^2]. Ixz = integral(x z dm), so the
        tensor's off-diagonal entry is -Ixz; Ixy = Iyz = 0 by the x-z plane of symmetry."""
        return np.array([[self.Ixx, 0.0, -self.Ixz], [0.0, self.Iyy, 0.0], [-self.Ixz, 0.0, self.Izz]])


@dataclass(frozen=True)
class HullParams:
    l_h: float = _f("m", "ESTIMATE", POSITIVE, "nose to fin-root leading edge (hull region)")
    I1: float = _f("m^2", "ESTIMATE", NONNEG, "Jones-DeLaurier integral I1 = A_h")
    I3: float = _f("m^3", "ESTIMATE", ANY, "Jones-DeLaurier integral I3 = l_h A_h - V_h")
    J1: float = _f("m^2", "ESTIMATE", NONNEG, "side-projected area of the hull region")
    J2: float = _f("m^3", "ESTIMATE", ANY, "first moment of J1 about the nose")
    CD0: float = _f("-", "ESTIMATE", NONNEG, "zero-alpha axial drag coefficient on V^(2/3)")
    Cdc: float = _f("-", "ESTIMATE", NONNEG, "cross-flow drag coefficient on J1")
    eta_k: float = _f("-", "CALIB", FRACTION, "hull efficiency factor (a fraction of the "
                      "slender-body lift)")


@dataclass(frozen=True)
class FinPanel:
    name: str = _f("-", "SOURCED", ANY, "panel name")
    roll_angle_deg: float = _f("deg", "SOURCED", ANY, "span direction (0, sin, cos) of this angle")
    cp_position: tuple = _f("m", "CALIB", VEC3, "quarter-chord mid-span point relative to the CM")


@dataclass(frozen=True)
class FinParams:
    planform_area: float = _f("m^2", "ESTIMATE", NONNEG, "planform area per fin")
    aspect_ratio: float = _f("-", "ESTIMATE", POSITIVE, "aspect ratio used for induced drag")
    CL_alpha: float = _f("1/rad", "CALIB", NONNEG, "3-D lift slope incl. hull interference loss; calibrated (0.68 x McCormick) to the 67.4 s lateral pendulum")
    alpha_stall_deg: float = _f("deg", "CALIB", STALL, "3-D stall angle of the low-aspect-ratio "
                                "fin (linear C_L below it); calibrated to a restoring static yaw "
                                "moment at every yaw offset to 90 deg")
    post_stall: str = _f("-", "SOURCED", ANY, "beyond stall: 'viterna' (Viterna-Corrigan normal "
                         "force to C_D,max at 90 deg) or 'flat' ([LN02]'s C_L held flat)")
    CD0: float = _f("-", "ESTIMATE", NONNEG, "parasite drag coefficient")
    oswald_e: float = _f("-", "ESTIMATE", EFFICIENCY, "Oswald efficiency (1: elliptic loading)")
    panels: tuple = _f("-", "SOURCED", ANY, "fin panels (inverted Y: upper, port, starboard)")


@dataclass(frozen=True)
class TetherParams:
    length: float = _f("m", "SOURCED", POSITIVE, "unstretched tether length paid out")
    n_elements: int = _f("-", "SOURCED", INT_GE1, "number of lumped-mass elements")
    diameter: float = _f("m", "SOURCED", POSITIVE, "tether diameter")
    density: float = _f("kg/m^3", "SOURCED", POSITIVE, "tether material density")
    youngs_modulus: float = _f("Pa", "SOURCED", POSITIVE, "effective Young's modulus")
    damping_ratio: float = _f("-", "SOURCED", NONNEG, "damping ratio zeta, b = zeta b_c")
    strength: float = _f("N", "SOURCED", POSITIVE, "breaking strength")
    Cd_normal: float = _f("-", "ESTIMATE", NONNEG, "normal drag coefficient")
    loading_fn: tuple = _f("-", "ESTIMATE", COEFFS, "f_n coefficients of [1, cos, sin, cos2, sin2]",
                           size=5)
    loading_ft: tuple = _f("-", "ESTIMATE", COEFFS, "f_t polynomial coefficients in phi, ascending",
                           size=6)
    anchor_position: tuple = _f("m", "ESTIMATE", VEC3, "winch / anchor position (inertial)")


@dataclass(frozen=True)
class WinchParams:
    equivalent_mass: float = _f("kg", "ESTIMATE", POSITIVE, "drivetrain inertia reflected to the line")
    coulomb_friction: float = _f("N", "ESTIMATE", NONNEG, "Coulomb friction at the line")
    viscous_friction: float = _f("N s/m", "ESTIMATE", NONNEG, "viscous friction at the line")
    max_motor_force: float = _f("N", "ESTIMATE", POSITIVE, "motor force limit at the line")
    max_speed: float = _f("m/s", "ESTIMATE", POSITIVE, "reel speed limit")
    max_acceleration: float = _f("m/s^2", "ESTIMATE", POSITIVE, "reel acceleration limit")
    speed_time_constant: float = _f("s", "ESTIMATE", POSITIVE, "closed speed-loop time constant")
    brake_speed: float = _f("m/s", "ESTIMATE", NONNEG,
                            "stand-still band: set-points below this count as 'stand still'")
    brake_dwell: float = _f("s", "ESTIMATE", NONNEG,
                            "the brake engages after the set-point stood still this long")
    brake_hold_speed: float = _f("m/s", "ESTIMATE", NONNEG,
                                 "drum speed below which the brake clamps (v_w set to 0)")
    min_length: float = _f("m", "ESTIMATE", POSITIVE, "shortest tether length")
    max_length: float = _f("m", "ESTIMATE", POSITIVE, "longest tether length")
    safe_working_load: float = _f("N", "ESTIMATE", POSITIVE, "over-tension threshold")
    slack_tension: float = _f("N", "ESTIMATE", NONNEG, "slack threshold")
    total_line_length: float = _f("m", "ESTIMATE", POSITIVE,
                                  "line on the winch, paid out plus on the drum (>= max_length)")


@dataclass(frozen=True)
class WindParams:
    profile: str = _f("-", "SOURCED", ANY, "mean profile: uniform, power or log")
    speed: float = _f("m/s", "SOURCED", NONNEG, "mean speed at the reference height")
    direction_deg: float = _f("deg", "ESTIMATE", ANY, "heading the wind blows toward, from +X to +Y")
    reference_height: float = _f("m", "ESTIMATE", POSITIVE, "reference height of power/log profiles")
    shear_exponent: float = _f("-", "ESTIMATE", NONNEG, "power-law exponent")
    roughness_length: float = _f("m", "ESTIMATE", POSITIVE, "log-law roughness length")
    turbulence: str = _f("-", "ESTIMATE", ANY, "turbulence preset: none, light, moderate or severe")
    turbulence_model: str = _f("-", "ESTIMATE", ANY, "turbulence spectrum: von_karman or dryden")
    turbulence_reference_height: float = _f("m", "ESTIMATE", POSITIVE,
                                            "height whose mean speed advects the frozen field and gusts")


@dataclass(frozen=True)
class SimulationParams:
    rk4_safety: float = _f("-", "ESTIMATE", POSITIVE, "fraction of the RK4 stability bound used")
    semi_implicit_dt: float = _f("s", "ESTIMATE", POSITIVE, "semi-implicit integrator step")


@dataclass(frozen=True)
class Params:
    """All parameters of one tethered-aerostat system. Immutable; use :meth:`replace`."""

    environment: EnvironmentParams
    aerostat: AerostatParams
    hull: HullParams
    fins: FinParams
    tether: TetherParams
    winch: WinchParams
    wind: WindParams
    simulation: SimulationParams
    #: Status of each value as the user's file states it ("section.key" -> SOURCED, ..., USER),
    #: read from the status comments of the TOML and set to USER by overrides; not compared.
    provenance: tuple = field(default=(), compare=False, repr=False)

    def replace(self, **dotted: Any) -> Params:
        """Return a copy with single values replaced, e.g. ``replace(**{"tether.length": 150})``."""
        return apply_overrides(self, dotted)

    @property
    def derived(self) -> Derived:
        return Derived.from_params(self)


SECTIONS = {
    "environment": EnvironmentParams,
    "aerostat": AerostatParams,
    "hull": HullParams,
    "fins": FinParams,
    "tether": TetherParams,
    "winch": WinchParams,
    "wind": WindParams,
    "simulation": SimulationParams,
}

WIND_PROFILES = ("uniform", "power", "log")
TURBULENCE_PRESETS = ("none", "light", "moderate", "severe")
TURBULENCE_MODELS = ("von_karman", "dryden")
POST_STALL_MODELS = ("viterna", "flat")

# --- validation ----------------------------------------------------------------------------------


def _check_value(name: str, value: Any, f: dataclasses.Field) -> Any:
    """Coerce and check one value against its field's declared type and constraint."""
    check = f.metadata["check"]
    if check == VEC3:
        if not (isinstance(value, (list, tuple)) and len(value) == 3 and all(map(is_number, value))):
            raise ParameterError(f"{name} must be a list of 3 numbers, got {value!r}")
        value = tuple(float(v) for v in value)
        if not all(math.isfinite(v) for v in value):
            raise ParameterError(f"{name} must be finite, got {value!r}")
        return value
    if check == COEFFS:
        size = f.metadata["size"]
        if not (isinstance(value, (list, tuple)) and value and all(map(is_number, value))):
            raise ParameterError(f"{name} must be a list of {size} numbers, got {value!r}")
        if len(value) != size:
            raise ParameterError(f"{name} needs {size} coefficients, got {len(value)}: {value!r}")
        value = tuple(float(v) for v in value)
        bad = [i for i, v in enumerate(value) if not math.isfinite(v)]
        if bad:
            raise ParameterError(f"{name} must be finite, got {value[bad[0]]!r} at index {bad[0]}")
        return value
    if f.type in ("str", str):
        if not isinstance(value, str):
            raise ParameterError(f"{name} must be a string, got {value!r}")
        return value
    if check == BOOL:
        if not isinstance(value, bool):
            raise ParameterError(f"{name} must be true or false, got {value!r}")
        return value
    if check == INT_GE1:
        if not is_whole(value, 1, MAX_ELEMENTS):
            typed = " (write it without a decimal point)" if (
                is_finite_number(value) and value == int(value) and 1 <= value <= MAX_ELEMENTS) else ""
            raise ParameterError(f"{name} must be an integer >= 1 and <= {MAX_ELEMENTS}, got "
                                 f"{value!r}{typed}")
        return int(value)
    if not is_number(value):
        raise ParameterError(f"{name} must be a number, got {value!r}")
    value = float(value)
    if not math.isfinite(value):
        raise ParameterError(f"{name} must be finite, got {value!r}")
    if check == POSITIVE and value <= 0:
        raise ParameterError(f"{name} must be > 0, got {value!r}")
    if check == NONNEG and value < 0:
        raise ParameterError(f"{name} must be >= 0, got {value!r}")
    if check == STALL and not 0 < value < 90:
        raise ParameterError(f"{name} must lie in (0, 90) deg, got {value!r}")
    if check == FRACTION and not 0 <= value <= 1:
        raise ParameterError(f"{name} must lie in [0, 1], got {value!r}")
    if check == EFFICIENCY and not 0 < value <= 1:
        raise ParameterError(f"{name} must lie in (0, 1], got {value!r}")
    return value


def _build(cls: type, name: str, table: Any) -> Any:
    if not isinstance(table, dict):
        raise ParameterError(f"[{name}] must be a table, got {table!r}")
    known = {f.name: f for f in fields(cls)}
    unknown = sorted(set(table) - set(known))
    if unknown:
        hints = [k + _did_you_mean(k, known) for k in unknown]
        raise ParameterError(f"unknown key(s) in [{name}]: {', '.join(hints)}")
    missing = sorted(set(known) - set(table))
    if missing:
        raise ParameterError(f"missing key(s) in [{name}]: {', '.join(missing)}")
    values = {}
    for key, f in known.items():
        if cls is FinParams and key == "panels":
            values[key] = _build_panels(table[key])
        else:
            values[key] = _check_value(f"{name}.{key}", table[key], f)
    return cls(**values)


def _build_panels(panels: Any) -> tuple:
    if not isinstance(panels, list) or not panels:
        raise ParameterError(f"fins.panels must be a non-empty array of tables, got {panels!r}")
    return tuple(_build(FinPanel, f"fins.panels[{i}]", p) for i, p in enumerate(panels))


def _cross_checks(p: Params) -> None:
    """Constraints between fields, checked after every load or override (after the ranges of
    single values no aerostat leaves, which the constraints' messages would otherwise print)."""
    _check_ranges(p)
    if p.wind.turbulence not in TURBULENCE_PRESETS:
        raise ParameterError(f"wind.turbulence must be one of {TURBULENCE_PRESETS}, got {p.wind.turbulence!r}")
    if p.wind.turbulence_model not in TURBULENCE_MODELS:
        raise ParameterError(
            f"wind.turbulence_model must be one of {TURBULENCE_MODELS}, got {p.wind.turbulence_model!r}")
    if p.fins.post_stall not in POST_STALL_MODELS:
        raise ParameterError(f"fins.post_stall must be one of {POST_STALL_MODELS}, got {p.fins.post_stall!r}")
    if p.wind.profile not in WIND_PROFILES:
        raise ParameterError(f"wind.profile must be one of {WIND_PROFILES}, got {p.wind.profile!r}")
    if p.wind.profile == "log" and not p.wind.roughness_length < p.wind.reference_height:
        raise ParameterError(
            f"wind.roughness_length = {p.wind.roughness_length:g} m must be below "
            f"wind.reference_height = {p.wind.reference_height:g} m for the log profile (its "
            "speed, U ln(z / z0) / ln(z_ref / z0), would blow against the wind)")
    if p.winch.min_length >= p.winch.max_length:
        raise ParameterError(
            f"winch.min_length ({p.winch.min_length}) must be < winch.max_length ({p.winch.max_length})"
        )
    check_length_within_winch(p)
    if p.hull.l_h > p.aerostat.length:
        raise ParameterError(f"hull.l_h = {p.hull.l_h} m (nose to the fins' root) must not exceed "
                             f"aerostat.length = {p.aerostat.length} m")
    check_inertia(p.aerostat.Ixx, p.aerostat.Iyy, p.aerostat.Izz, p.aerostat.Ixz)
    if not -89.0 < p.aerostat.trim_pitch_deg < 89.0:
        raise ParameterError(f"aerostat.trim_pitch_deg must lie in (-89, 89), got {p.aerostat.trim_pitch_deg}")
    d = Derived.from_params(p)
    if d.net_lift <= 0:
        raise ParameterError(
            f"aerostat.mass = {p.aerostat.mass} kg gives no net lift (buoyancy {d.buoyancy:.1f} N "
            f"<= weight {p.aerostat.mass * p.environment.g:.1f} N)"
        )
    _feasibility(p, d)
    check_limits(p)


class InertiaError(ParameterError):
    """Moments of inertia no mass distribution has (raised by :func:`check_inertia`). A joint
    constraint: no single moment decides it, so range checks that move one parameter at a time
    treat it apart (a domain randomisation redraws such a set)."""


def check_inertia(ixx: float, iyy: float, izz: float, ixz: float) -> None:
    """The body's inertia tensor must be one a mass distribution can have. (1) Positive definite:
    the x-z block [[Ixx, -Ixz], [-Ixz, Izz]] needs Ixz^2 < Ixx Izz (Ixx, Iyy, Izz > 0 are checked
    field by field); with an indefinite tensor the kinetic energy (1/2) w.I.w is negative for
    some rotations and the motion diverges (Ixz = -30000 kg m^2 on the baseline did, at 5.6 s).
    (2) The triangle inequalities: each principal moment is at most the sum of the other two,
    since e.g. I1 + I2 - I3 = 2 * integral of (the third axis coordinate)^2 dm >= 0. The
    principal moments are Iyy and the x-z block's eigenvalues l+, l- (sum Ixx + Izz, difference
    sqrt((Ixx - Izz)^2 + 4 Ixz^2)), so the inequalities read Iyy <= Ixx + Izz and
    l+ - l- <= Iyy. Equality (a flat body) is allowed. Raises :class:`InertiaError`."""
    if ixz ** 2 >= ixx * izz:
        raise InertiaError(
            f"aerostat.Ixz = {ixz} kg m^2 makes the inertia tensor indefinite: a rigid body needs "
            f"|Ixz| < sqrt(aerostat.Ixx * aerostat.Izz) = sqrt({ixx} * {izz}) = "
            f"{math.sqrt(ixx * izz):.1f} kg m^2")
    tol = 1e-12 * (ixx + iyy + izz)  # rounding of an exactly flat body
    if iyy > ixx + izz + tol:
        raise InertiaError(
            f"aerostat.Iyy = {iyy} kg m^2 exceeds aerostat.Ixx + aerostat.Izz = {ixx} + "
            f"{izz} = {ixx + izz:.1f} kg m^2: no mass distribution has such moments "
            "(Ixx + Izz - Iyy = 2 * integral of y^2 dm must be >= 0)")
    spread = math.hypot(ixx - izz, 2.0 * ixz)
    if spread > iyy + tol:
        raise InertiaError(
            f"aerostat.Ixx = {ixx}, aerostat.Izz = {izz} and aerostat.Ixz = {ixz} kg m^2 "
            f"give x-z principal moments {spread:.1f} kg m^2 apart, more than aerostat.Iyy = "
            f"{iyy} kg m^2: no mass distribution has such moments (each principal moment is "
            "at most the sum of the other two)")


def _feasibility(p: Params, d: Derived) -> None:
    """Constraints across sections without which no episode can run: each error names both
    fields and their numbers."""
    t, w = p.tether, p.winch
    if w.total_line_length < w.max_length:
        raise ParameterError(
            f"winch.total_line_length ({w.total_line_length} m) must be >= winch.max_length "
            f"({w.max_length} m): the drum cannot pay out more line than it holds")
    if d.net_lift <= d.tether_weight:
        raise ParameterError(
            f"the net lift ({d.net_lift:.1f} N, aerostat.volume and aerostat.mass) does not "
            f"exceed the weight of tether.length = {t.length} m of tether ({d.tether_weight:.1f} N, "
            "tether.diameter and tether.density): the aerostat cannot lift its tether")
    if d.net_lift >= t.strength:
        raise ParameterError(
            f"the net lift ({d.net_lift:.1f} N, aerostat.volume and aerostat.mass), the tether "
            f"tension in still air, is not below tether.strength ({t.strength} N): the tether "
            "breaks at zero wind")
    if w.safe_working_load > t.strength:
        raise ParameterError(
            f"winch.safe_working_load ({w.safe_working_load} N) exceeds tether.strength "
            f"({t.strength} N)")
    if w.slack_tension >= w.safe_working_load:
        raise ParameterError(
            f"winch.slack_tension ({w.slack_tension} N) must be below winch.safe_working_load "
            f"({w.safe_working_load} N)")


#: The semi-implicit step measured on the shipped baseline, whose hull is 18.3 m long (both
#: values are the baseline file's; tests/test_own_aerostat.py checks they stay so): no
#: numerical failure in the 1,000,320-step random-action soak (README "Guarantees"). The step is
#: bounded by the explicit aerodynamics, whose time scales shrink with the hull under Froude
#: similarity as sqrt(length) (aerostat_gym.scaling applies the same law).
SEMI_IMPLICIT_REFERENCE_HULL_LENGTH = 18.3
SEMI_IMPLICIT_REFERENCE_DT = 0.05


def froude_step(step: float, length_ratio: float) -> float:
    """A semi-implicit step carried to an aerostat ``length_ratio`` times as long: shortened
    by sqrt(length_ratio) for a smaller one (Froude time scaling), never lengthened."""
    return step * min(1.0, math.sqrt(length_ratio))


#: [m/s] normal air speed across the tether at which its drag, explicit in the semi-implicit
#: step, must stay stable (CALIB: 40 generated aerostats, 0.003-10x the baseline's volume, in
#: severe turbulence at 15-25 m/s, 8 x 500 random-reeling steps each at their Froude-scaled
#: step, and the smallest at shorter steps: numerical failures only where the step's h lambda
#: at 12.5 m/s was 2.0 or more (1 at 2.0, 1-3 at 2.3-2.7, 11 at 2.9), none below in 36
#: configurations. 15 m/s puts the advised step a sixth inside that edge).
TETHER_DRAG_REFERENCE_SPEED = 15.0


def tether_drag_step(diameter: float, density: float, Cd_normal: float, rho_air: float) -> float:
    """The longest semi-implicit step whose explicit tether drag is stable [s]: explicit Euler
    needs h lambda <= 2 on the drag's rate lambda = 2 rho_air Cd d v_n / mu (the quadratic
    drag's derivative along the normal velocity, per unit mass of line, mu = density pi d^2/4)
    at v_n = TETHER_DRAG_REFERENCE_SPEED. The rate grows as 1/d, so a thin line needs a short
    step: 0.19 s for the baseline's 6 mm line (not the bound), 11 ms for a 0.35 mm one."""
    mu = density * math.pi * diameter**2 / 4.0
    rate = 2.0 * rho_air * Cd_normal * diameter * TETHER_DRAG_REFERENCE_SPEED / mu
    return 2.0 / rate if rate > 0.0 else math.inf  # a drag-free line sets no bound


def advised_semi_implicit_dt(p: Params) -> float:
    """The longest semi-implicit step advised for this aerostat [s]: the baseline's 50 ms
    scaled by sqrt(hull length / 18.3 m) for a shorter hull (50 ms for a longer one), and no
    longer than the tether drag's explicit bound (:func:`tether_drag_step`)."""
    t = p.tether
    return min(froude_step(SEMI_IMPLICIT_REFERENCE_DT,
                           p.aerostat.length / SEMI_IMPLICIT_REFERENCE_HULL_LENGTH),
               tether_drag_step(t.diameter, t.density, t.Cd_normal, p.environment.rho_air))


def _advise(p: Params, source: str) -> None:
    """Warn (:class:`ParameterWarning`) when a loaded file holds values that run but invite
    numerical failures (once, at the door: not on every override)."""
    advised = advised_semi_implicit_dt(p)
    if p.simulation.semi_implicit_dt > advised * (1.0 + 1e-9):
        warnings.warn(
            f"{source}: simulation.semi_implicit_dt = {p.simulation.semi_implicit_dt:g} s is "
            f"longer than {advised:.3g} s, the shorter of the baseline's "
            f"{SEMI_IMPLICIT_REFERENCE_DT:g} s scaled to this {p.aerostat.length:.3g} m hull "
            "(aerostat.length; sqrt of the length ratio) and the explicit bound of the drag on "
            f"this {1000 * p.tether.diameter:.3g} mm tether (tether.diameter): episodes in "
            "strong turbulence may end as numerical_divergence (the baseline scaled to 0.1x "
            "its volume, severe turbulence, random reeling: 1 in 40,000 steps at 50 ms, none "
            f"at 34 ms). Set simulation.semi_implicit_dt <= {advised:.3g}, or use "
            "integrator='rk4'",
            ParameterWarning, stacklevel=3)
    for text in hull_integral_warnings(p):
        warnings.warn(f"{source}: {text}: check the hull integrals (docs/parameters.md, "
                      "section 1c)", ParameterWarning, stacklevel=3)
    for text in plausibility_warnings(p):
        warnings.warn(f"{source}: {text} (docs/parameters.md, section 1k)", ParameterWarning,
                      stacklevel=3)


def hull_integral_warnings(p: Params) -> list[str]:
    """What the Jones-DeLaurier integrals of the hull region (nose to l_h) say that no hull can
    have: V_h = l_h I1 - I3, the volume ahead of l_h, outside [0, aerostat.volume], or the
    centroid J2 / J1 of the side area outside [0, l_h]."""
    h, volume = p.hull, p.aerostat.volume
    out = []
    v_h = h.l_h * h.I1 - h.I3
    if not 0.0 <= v_h <= volume:
        out.append(f"hull.I3 = {h.I3:g} m^3 with hull.l_h = {h.l_h:g} m and hull.I1 = {h.I1:g} "
                   f"m^2 puts {v_h:.4g} m^3 of hull ahead of l_h (V_h = l_h I1 - I3), outside "
                   f"[0, aerostat.volume = {volume:g}]")
    if h.J1 > 0.0 and not 0.0 <= h.J2 / h.J1 <= h.l_h:
        out.append(f"hull.J2 / hull.J1 = {h.J2 / h.J1:.4g} m, the centroid of the hull's side "
                   f"area, lies outside the hull region [0, hull.l_h = {h.l_h:g}] m")
    return out


# --- plausibility: values that pass their own field's check but no real aerostat has -----------
#
# A unit slip (MPa written as Pa, cm as m) passes every per-field check and the feasibility
# checks, loads, and then fails every episode at step 0 far from its cause. The bounds below are
# refused at the door (:func:`check_plausibility`, run by load_params on the file and its overrides
# alike, and by the environment when it is made); values that are unusual but possible only warn
# (:func:`plausibility_warnings`, a ParameterWarning). Every bound is generous: aerostats from 5 m
# to 70 m hulls, tethers from 20 m to 5 km of Dyneema, Kevlar, Vectran, polyester or steel-armoured
# conductor cable all pass. They are not checked by Params.replace / apply_overrides, so that
# studies may still move one value past them on purpose (a weightless tether, RK4 past its
# stability bound) in the simulator.


class ImplausibleParameterError(ParameterError):
    """A value that passes its field's own check but no real aerostat or tether has, most often
    a unit slip; the message names the field, the value, the bound and the likely slip."""


#: Largest number of fin panels: the compiled core packs the panels into a fixed-size block
#: (aerostat_gym.physics.packing.MAX_FINS is this constant; params sits below the physics
#: layer, so the core imports it from here).
MAX_FIN_PANELS = 6
#: [m/s] the fastest mean wind the model is defined for (every door checks this one): the
#: aerodynamics are incompressible (one air density everywhere), valid below Mach 0.3, about
#: 100 m/s at sea level. Tethered aerostats are flown far below it (the baseline's tether breaks at trim near
#: 60 m/s). README "Guarantees": a faster mean wind is refused.
MAX_WIND_SPEED = 100.0
#: simulation.rk4_safety above this is past the measured stability edge of the RK4 step
#: (aerostat_gym.physics.integrators.rk4_step: runs at 1.02 times the bound 2 sqrt(2) / omega_max
#: stay stable, the element damping moving the axial eigenvalues off the imaginary axis; beyond
#: that the axial tether modes leave RK4's stability region and every episode diverges).
RK4_SAFETY_LIMIT = 1.02
#: simulation.semi_implicit_dt above this many times the advised step is refused: the steps
#: that failed in the calibration of TETHER_DRAG_REFERENCE_SPEED and of the Froude-scaled
#: step began at 1.2 x (h lambda 2.0 at 12.5 m/s) and 1.5 x (50 ms on the baseline scaled to
#: 0.1 x its volume, advised 34 ms) the advised step; past twice it no episode in strong wind
#: can be trusted, and a break from a blown-up step would read as physics.
SEMI_IMPLICIT_REFUSE_FACTOR = 2.0
#: Strain of the tether at its breaking strength, tether.strength / EA. Fibre ropes break at a
#: few % (HMPE/Dyneema 3-4 %, aramid/Kevlar 2-4 %, Vectran 3-5 %, steel 1-2 %, polyester
#: 12-15 %); nylon, the stretchiest rope fibre, at 20-40 %. Above WARN: unusual (a nylon-like
#: line); above MAX: no rope stretches to twice its length before breaking.
TETHER_BREAK_STRAIN_WARN = 0.25
TETHER_BREAK_STRAIN_MAX = 1.0
#: Strain of the tether under the still-air net lift, net lift / EA: a tether is loaded at a
#: fraction of its strength, so a real one stretches well under 10 %; a modulus so low that
#: the net lift stretches the line by half its length is a unit slip.
TETHER_LIFT_STRAIN_MAX = 0.5
#: [Pa] diamond's Young's modulus is about 1.05e12 Pa; no tether is stiffer (steel 2.0e11,
#: carbon fibre up to 6e11, HMPE fibre 1.1e11).
TETHER_MODULUS_MAX = 1.2e12
#: [kg/m^3] the tether's effective density, mass per length / (pi d^2 / 4). Rope fibres range
#: from polypropylene's 910 (HMPE 970, aramid 1440, polyester 1380) to steel's 7850 and copper's
#: 8960; a braid's voids take the effective value down to about half. Outside WARN: unusual;
#: outside MAX: no solid is that light (a foam rope is still > 50) or heavier than tungsten.
TETHER_DENSITY_WARN = (400.0, 9000.0)
TETHER_DENSITY_MAX = (50.0, 20000.0)
#: Prismatic coefficient volume / (pi d^2 L / 4), the hull's share of the cylinder enclosing it.
#: Convex bodies of revolution lie between the double cone's 1/3 and the cylinder's 1; helium
#: fins can add a few %. Streamlined hulls have 0.55-0.7 (an ellipsoid 0.667, the baseline
#: 0.609). Outside WARN: unusual; outside MAX: a unit slip (d in cm shrinks it 10^4-fold).
HULL_PRISMATIC_WARN = (0.4, 0.85)
HULL_PRISMATIC_MAX = (0.25, 1.1)
#: Fineness ratio length / diameter: a spherical balloon has 1, aerostats 2.2-4, the slimmest
#: airships about 8 (ZR-3 7.3). Below MIN the hull is shorter than its diameter (length and
#: diameter swapped?); above WARN unusual; above MAX no hull.
HULL_FINENESS_MIN, HULL_FINENESS_WARN, HULL_FINENESS_MAX = 0.9, 8.0, 20.0
#: A fin's quarter-chord mid-span point may sit this many hull lengths aft of the tail (fins
#: overhanging the tail on a short hull), and at most this many diameters off the hull axis
#: (the baseline's fins: 0.6 D; the span of an aerostat fin is at most about a diameter).
FIN_AFT_OF_TAIL = 0.25
FIN_RADIUS_MAX = 2.0
#: The confluence point hangs at most this many hull lengths below the CM (the [LN02] rule puts
#: it 1.5 D below the axis, 0.63 L on the baseline; long flying lines reach about a hull length).
LEASH_DEPTH_MAX = 3.0
#: hull.Cdc: the cross-flow drag coefficient of the hull's sections; a circular cylinder has
#: 0.3-1.2 (super- to subcritical), a flat plate 2.0, a concave half-cylinder face 2.3, the
#: largest of any section. Above WARN: unusual; above MAX: no section.
HULL_CDC_WARN, HULL_CDC_MAX = 1.5, 3.0


def _slip(value: float, factors: dict[str, float], ok) -> str:
    """``; looks like <slip>`` for the first unit slip whose correction factor makes ``ok``
    true, or an empty string."""
    for text, factor in factors.items():
        if ok(value * factor):
            return f"; looks like {text}"
    return ""


def _div(a: float, b: float) -> float:
    """a / b for a >= 0, b >= 0 that underflowed or overflowed: inf where b is 0 (a bound then
    refuses it instead of a ZeroDivisionError)."""
    return a / b if b > 0.0 else math.inf


def check_limits(p: Params) -> None:
    """Limits of the compiled core and of the model's validity, checked on every load and
    override: at most MAX_FIN_PANELS fin panels, a mean wind of at most MAX_WIND_SPEED, and the
    winch on or above the ground (heights are measured from the ground, z = 0)."""
    n = len(p.fins.panels)
    if n > MAX_FIN_PANELS:
        raise ParameterError(f"fins.panels has {n} panels; at most {MAX_FIN_PANELS} fin panels "
                             "are supported (the compiled core's fixed fin block)")
    if p.wind.speed > MAX_WIND_SPEED:
        raise ParameterError(
            f"wind.speed = {p.wind.speed:g} m/s exceeds {MAX_WIND_SPEED:g} m/s, the fastest mean "
            "wind the model is defined for (incompressible aerodynamics, Mach < 0.3)"
            + _slip(p.wind.speed, {"km/h written as m/s": 1 / 3.6}, lambda v: v <= MAX_WIND_SPEED))
    z0 = p.tether.anchor_position[2]
    if z0 < 0.0:
        raise ParameterError(
            f"tether.anchor_position = {list(p.tether.anchor_position)} puts the winch at "
            f"z = {z0:g} m, below the ground (z = 0): its z must be >= 0 (the wind profile and "
            "the ground strike read heights above the ground)")


#: Bounds of single values that no aerostat on any planet leaves, (low, high, what is usual):
#: past them the model fails far from the cause (a drag coefficient of 1e300 stalls the trim
#: with a residual of 1e277, a damping ratio of 1e6 diverges every episode at its first step).
PLAUSIBLE_RANGES = {
    "environment.g": (0.1, 100.0, "m/s^2: Earth 9.81, Mars 3.7, Jupiter 24.8"),
    "environment.rho_air": (1e-3, 100.0, "kg/m^3: 1.225 at sea level, 65 on Venus' surface"),
    "tether.damping_ratio": (0.0, 2.0, "twice critical damping; [LN02] uses 0.017"),
    "hull.CD0": (0.0, 2.0, "streamlined hulls 0.02-0.05 on V^(2/3), a blunt body about 1"),
    "fins.CD0": (0.0, 2.0, "fin panels 0.008-0.02, a flat plate broadside 2"),
    "fins.CL_alpha": (0.0, 4.0 * math.pi, "per radian: a thin airfoil 2 pi, low-aspect fins "
                                          "1-3"),
}


def _check_ranges(p: Params) -> None:
    """:data:`PLAUSIBLE_RANGES`, each an ImplausibleParameterError naming the field, with the
    likely slip of a percentage where a hundredth of the value is in range."""
    for key, (low, high, usual) in PLAUSIBLE_RANGES.items():
        section, name = key.split(".")
        value = getattr(getattr(p, section), name)
        if not low <= value <= high:
            raise ImplausibleParameterError(
                f"{key} = {value:g} lies outside [{low:g}, {high:g}] ({usual})"
                + _slip(value, {"a percentage written as a fraction": 0.01},
                        lambda v, lo=low, hi=high: lo <= v <= hi))


def check_plausibility(p: Params) -> None:
    """Refuse values that load but no real aerostat has (:class:`ImplausibleParameterError`),
    naming the field, the value, the bound and the likely slip. Run by :func:`load_params` and
    when an environment is made (:data:`PLAUSIBLE_RANGES` on every load and replace too)."""
    _plausible_tether(p)
    _plausible_hull(p)
    _plausible_body_points(p)
    _plausible_numerics(p)


def _plausible_tether(p: Params) -> None:
    """The tether's stiffness (its stretch under its own breaking strength and under the net
    lift) and its effective density."""
    t, d = p.tether, p.derived
    E = t.youngs_modulus
    break_strain, lift_strain = _div(t.strength, d.EA), _div(d.net_lift, d.EA)
    if E > TETHER_MODULUS_MAX:
        raise ImplausibleParameterError(
            f"tether.youngs_modulus = {E:g} Pa exceeds {TETHER_MODULUS_MAX:g} Pa, stiffer than "
            "diamond" + _slip(E, {"kPa written as Pa": 1e-3, "MPa written as Pa": 1e-6},
                              lambda v: v <= TETHER_MODULUS_MAX))
    if break_strain > TETHER_BREAK_STRAIN_MAX or lift_strain > TETHER_LIFT_STRAIN_MAX:
        ok = lambda v: (_div(t.strength, v * d.tether_area) <= TETHER_BREAK_STRAIN_WARN  # noqa: E731
                        and _div(d.net_lift, v * d.tether_area) <= TETHER_LIFT_STRAIN_MAX)
        raise ImplausibleParameterError(
            f"tether.youngs_modulus = {E:g} Pa gives EA = {d.EA:.4g} N on the "
            f"{1000 * t.diameter:g} mm tether (tether.diameter): it would stretch by "
            f"{100 * lift_strain:.3g} % under the net lift ({d.net_lift:.1f} N) and by "
            f"{100 * break_strain:.3g} % at tether.strength ({t.strength:g} N); a real tether "
            f"stretches a few % at break (bounds: {100 * TETHER_LIFT_STRAIN_MAX:g} % under the "
            f"net lift, {100 * TETHER_BREAK_STRAIN_MAX:g} % at break)"
            + _slip(E, {"MPa written as Pa": 1e6, "GPa written as Pa": 1e9,
                        "GPa written as MPa": 1e3}, ok))
    rho_t = t.density
    lo, hi = TETHER_DENSITY_MAX
    if not lo <= rho_t <= hi:
        raise ImplausibleParameterError(
            f"tether.density = {rho_t:g} kg/m^3 (a {1000 * d.mass_per_length:.4g} g/m line at "
            f"tether.diameter = {1000 * t.diameter:g} mm) lies outside [{lo:g}, {hi:g}] kg/m^3, "
            "the effective density of any rope or cable (it is the material density, kg/m^3, "
            "not the mass per length)"
            + _slip(rho_t, {"g/cm^3 written as kg/m^3": 1e3, "kg/m (mass per length) written "
                            "as kg/m^3": 1.0 / d.tether_area}, lambda v: lo <= v <= hi))


def _plausible_hull(p: Params) -> None:
    """Length, diameter and volume must describe one body."""
    a = p.aerostat
    cyl = math.pi / 4.0 * a.diameter * a.diameter * a.length  # inf, not OverflowError
    prismatic, fineness = _div(a.volume, cyl), _div(a.length, a.diameter)
    lo, hi = HULL_PRISMATIC_MAX
    if not lo <= prismatic <= hi:
        raise ImplausibleParameterError(
            f"aerostat.volume = {a.volume:g} m^3 is {prismatic:.3g} times the cylinder "
            f"pi d^2 L / 4 = {cyl:.4g} m^3 enclosing aerostat.length = {a.length:g} m and "
            f"aerostat.diameter = {a.diameter:g} m; a hull fills {lo:g}..{hi:g} of it "
            "(streamlined hulls 0.55-0.7)"
            + _slip(prismatic, {"aerostat.diameter in cm": 1e4, "aerostat.length in cm": 1e2,
                                "aerostat.diameter in mm": 1e6, "aerostat.volume in litres": 1e-3,
                                "aerostat.diameter written as the radius": 0.25},
                    lambda v: lo <= v <= hi))
    if not HULL_FINENESS_MIN <= fineness <= HULL_FINENESS_MAX:
        raise ImplausibleParameterError(
            f"aerostat.length / aerostat.diameter = {a.length:g} / {a.diameter:g} = "
            f"{fineness:.3g} lies outside [{HULL_FINENESS_MIN:g}, {HULL_FINENESS_MAX:g}] (a "
            "sphere has 1, aerostats 2.2-4, the slimmest airships about 8)"
            + ("; looks like length and diameter swapped" if fineness < 1 else ""))


def _plausible_body_points(p: Params) -> None:
    """The CB, the nose, the fins and the confluence point: in the x-z symmetry plane, and
    inside (or for fins and the confluence point, near) the hull's length envelope."""
    a = p.aerostat
    L, D = a.length, a.diameter
    x_nose, y_nose, z_axis = a.nose_position
    tol = 1e-6 * L  # rounding of a point written in the symmetry plane
    for name, y in (("aerostat.cb_position", a.cb_position[1]), ("aerostat.nose_position", y_nose)):
        if abs(y) > tol:
            raise ImplausibleParameterError(
                f"{name} = {list(getattr(a, name.split('.')[1]))} has y = {y:g} m: the model "
                "assumes the x-z plane through the CM is a plane of symmetry (Ixy = Iyz = 0, "
                "leash point at y = 0), so the CB and the nose need y = 0")
    if not 0.0 < x_nose < L:
        raise ImplausibleParameterError(
            f"aerostat.nose_position x = {x_nose:g} m puts the CM "
            + ("ahead of the nose" if x_nose <= 0 else f"{x_nose - L:g} m behind the tail")
            + f" of the aerostat.length = {L:g} m hull: the nose must lie 0 < x < {L:g} m ahead "
            "of the CM" + ("; looks like the sign was flipped (x points to the nose)"
                           if 0 < -x_nose < L else ""))
    x_tail = x_nose - L
    if not x_tail <= a.cb_position[0] <= x_nose:
        raise ImplausibleParameterError(
            f"aerostat.cb_position x = {a.cb_position[0]:g} m lies outside the hull, which runs "
            f"from the tail at x = {x_tail:g} m to the nose at x = {x_nose:g} m "
            "(aerostat.nose_position, aerostat.length)")
    for i, pan in enumerate(p.fins.panels):
        x, y, z = pan.cp_position
        aft = x_tail - FIN_AFT_OF_TAIL * L
        if not aft <= x <= x_nose:
            raise ImplausibleParameterError(
                f"fins.panels[{i}].cp_position x = {x:g} m lies outside [{aft:g}, {x_nose:g}] m: "
                f"the hull runs from x = {x_tail:g} m (tail) to {x_nose:g} m (nose, "
                f"aerostat.nose_position, aerostat.length = {L:g} m), and a fin may sit at most "
                f"{FIN_AFT_OF_TAIL:g} hull lengths aft of the tail")
        r = math.hypot(y, z - z_axis)
        if r > FIN_RADIUS_MAX * D:
            raise ImplausibleParameterError(
                f"fins.panels[{i}].cp_position = {list(pan.cp_position)} lies {r:.4g} m from the "
                f"hull axis (z = {z_axis:g} m, aerostat.nose_position), more than "
                f"{FIN_RADIUS_MAX:g} x aerostat.diameter = {FIN_RADIUS_MAX * D:g} m")
    zl = a.leash_z
    if zl >= 0.0:
        raise ImplausibleParameterError(
            f"aerostat.leash_z = {zl:g} m puts the confluence point at or above the CM; body z "
            "points up, and the confluence point hangs below the hull: leash_z must be < 0"
            + ("; looks like the sign was flipped" if zl <= LEASH_DEPTH_MAX * L else ""))
    if -zl > LEASH_DEPTH_MAX * L:
        raise ImplausibleParameterError(
            f"aerostat.leash_z = {zl:g} m puts the confluence point {-zl / L:.3g} hull lengths "
            f"below the CM (bound {LEASH_DEPTH_MAX:g} x aerostat.length = {LEASH_DEPTH_MAX * L:g}"
            " m; the [LN02] rule is 1.5 diameters below the axis)"
            + _slip(zl, {"cm written as m": 0.01}, lambda v: -v <= LEASH_DEPTH_MAX * L))


def _plausible_numerics(p: Params) -> None:
    """The cross-flow drag coefficient and the integration steps."""
    if p.hull.Cdc > HULL_CDC_MAX:
        raise ImplausibleParameterError(
            f"hull.Cdc = {p.hull.Cdc:g} exceeds {HULL_CDC_MAX:g}: no cross-section has a "
            "cross-flow drag coefficient above about 2.3 (circular cylinders 0.3-1.2, a flat "
            "plate 2.0)")
    s = p.simulation.rk4_safety
    if s > RK4_SAFETY_LIMIT:
        raise ImplausibleParameterError(
            f"simulation.rk4_safety = {s:g} exceeds {RK4_SAFETY_LIMIT:g}, the measured stability "
            "limit: it is the fraction of the RK4 stability bound 2 sqrt(2) / omega_max used as "
            "the step, so every rk4 episode would diverge (the shipped files use 0.9)"
            + ("; looks like a percentage written as a fraction" if s >= 10.0
               and s / 100.0 <= RK4_SAFETY_LIMIT else ""))
    dt, advised = p.simulation.semi_implicit_dt, advised_semi_implicit_dt(p)
    if dt > SEMI_IMPLICIT_REFUSE_FACTOR * advised:
        raise ImplausibleParameterError(
            f"simulation.semi_implicit_dt = {dt:g} s is more than "
            f"{SEMI_IMPLICIT_REFUSE_FACTOR:g} x the {advised:.3g} s advised for this aerostat "
            "(params.advised_semi_implicit_dt), past the measured edge where the step fails (1.2-1.5 x): an unstable step can load the "
            "tether past its strength, and such a break could not be told from a real one. Set "
            f"simulation.semi_implicit_dt <= {advised:.3g} (a step up to "
            f"{SEMI_IMPLICIT_REFUSE_FACTOR:g} x loads with a warning)")


def paid_out_weight(p: Params, length: float | None = None) -> float:
    """Weight [N] of ``length`` metres of tether (default ``tether.length``: the derived
    ``tether_weight``)."""
    return p.derived.mass_per_length * (p.tether.length if length is None else length) \
        * p.environment.g


def plausibility_warnings(p: Params) -> list[str]:
    """Values that are unusual but possible (a ParameterWarning each at load)."""
    a, t, d = p.aerostat, p.tether, p.derived
    out = []
    strain = _div(t.strength, d.EA)
    if strain > TETHER_BREAK_STRAIN_WARN:
        out.append(f"tether.youngs_modulus = {t.youngs_modulus:g} Pa stretches the tether by "
                   f"{100 * strain:.3g} % at tether.strength = {t.strength:g} N, more than a "
                   f"nylon rope's (HMPE, aramid and steel break at 1-5 %; warning above "
                   f"{100 * TETHER_BREAK_STRAIN_WARN:g} %)")
    lo, hi = TETHER_DENSITY_WARN
    if not lo <= t.density <= hi:
        out.append(f"tether.density = {t.density:g} kg/m^3 ({1000 * d.mass_per_length:.4g} g/m "
                   f"at tether.diameter = {1000 * t.diameter:g} mm) lies outside "
                   f"[{lo:g}, {hi:g}] kg/m^3, the effective density of fibre ropes and "
                   "steel-armoured cables")
    lo, hi = HULL_PRISMATIC_WARN
    prismatic = _div(a.volume, math.pi / 4.0 * a.diameter * a.diameter * a.length)
    if not lo <= prismatic <= hi:
        out.append(f"aerostat.volume = {a.volume:g} m^3 is {prismatic:.3g} of the cylinder "
                   "enclosing aerostat.length and aerostat.diameter (streamlined hulls: "
                   f"0.55-0.7; warning outside [{lo:g}, {hi:g}])")
    fineness = _div(a.length, a.diameter)
    if fineness > HULL_FINENESS_WARN:
        out.append(f"aerostat.length / aerostat.diameter = {fineness:.3g} is slimmer than any "
                   f"airship (warning above {HULL_FINENESS_WARN:g})")
    if p.hull.Cdc > HULL_CDC_WARN:
        out.append(f"hull.Cdc = {p.hull.Cdc:g} is above a circular cylinder's 0.3-1.2 "
                   f"(warning above {HULL_CDC_WARN:g})")
    full = paid_out_weight(p, p.winch.max_length)
    if d.net_lift <= full:
        reach = d.net_lift / paid_out_weight(p, 1.0)
        out.append(f"the net lift ({d.net_lift:.1f} N) does not exceed the weight of "
                   f"winch.max_length = {p.winch.max_length:g} m of tether ({full:.1f} N): paid "
                   f"out past {reach:.0f} m, the line rests on the wind's lift alone, and in "
                   "light wind the model (which has no ground for the tether) hangs it below the "
                   "winch; lower winch.max_length or widen the margin")
    out.extend(_fin_symmetry_warnings(p))
    return out


def _fin_symmetry_warnings(p: Params) -> list[str]:
    """Fin panels without a mirror image in the x-z plane (cp (x, -y, z), roll angle -phi): the
    forces are computed panel by panel, so such a set runs, but the linear analyses and the
    trim in the x-z plane assume the aerostat's symmetry."""
    panels, L = p.fins.panels, p.aerostat.length

    def mirrored(a: FinPanel, b: FinPanel) -> bool:
        (xa, ya, za), (xb, yb, zb) = a.cp_position, b.cp_position
        dphi = (a.roll_angle_deg + b.roll_angle_deg + 180.0) % 360.0 - 180.0
        return (max(abs(xa - xb), abs(ya + yb), abs(za - zb)) <= 1e-3 * L and abs(dphi) <= 0.5)

    return [f"fins.panels[{i}] ({pan.name!r}, cp_position {list(pan.cp_position)}, "
            f"roll_angle_deg {pan.roll_angle_deg:g}) has no mirror panel in the x-z plane "
            "(cp_position with -y, roll_angle_deg negated): the model assumes x-z symmetry"
            for i, pan in enumerate(panels) if not any(mirrored(pan, q) for q in panels)]


def check_length_within_winch(p: Params) -> None:
    """The paid-out tether length must lie inside the winch's length limits: beyond
    winch.max_length the drum would hold a negative length of line (and negative mass)."""
    L, w = p.tether.length, p.winch
    if not w.min_length <= L <= w.max_length:
        raise ParameterError(
            f"tether.length = {L} m lies outside the winch's limits winch.min_length = "
            f"{w.min_length} m .. winch.max_length = {w.max_length} m")


def params_from_dict(data: dict) -> Params:
    """Build :class:`Params` from a nested dict (the parsed TOML), strictly."""
    if not isinstance(data, dict):
        raise ParameterError("parameter data must be a table")
    unknown = sorted(set(data) - set(SECTIONS))
    if unknown:
        hints = [k + _did_you_mean(k, SECTIONS) for k in unknown]
        raise ParameterError(f"unknown section(s): {', '.join(hints)}")
    missing = [s for s in SECTIONS if s not in data]
    if missing:
        raise ParameterError(f"missing section(s): {', '.join(missing)}")
    p = Params(**{name: _build(cls, name, data[name]) for name, cls in SECTIONS.items()})
    _cross_checks(p)
    return p


def params_to_dict(p: Params) -> dict:
    """Nested plain dict of all inputs (round-trips through :func:`params_from_dict`)."""
    out = {}
    for name in SECTIONS:
        sec = dataclasses.asdict(getattr(p, name))
        out[name] = {k: (list(v) if isinstance(v, tuple) and k != "panels" else v) for k, v in sec.items()}
    out["fins"]["panels"] = [
        {**pan, "cp_position": list(pan["cp_position"])} for pan in out["fins"]["panels"]
    ]
    return out


def parameter_key(data: dict, key: str) -> tuple[str, str]:
    """``(section, name)`` of a dotted parameter name (``"hull.Cdc"``) in a parameter
    dictionary (:func:`params_to_dict`); an unknown one is a ParameterError naming the nearest
    known name."""
    sec, dot, name = str(key).partition(".")
    if dot and sec in SECTIONS and name in data[sec]:
        return sec, name
    hint = _did_you_mean(str(key), [f"{s}.{k}" for s in SECTIONS for k in data[s]])
    if not hint:
        hint = f" (use 'section.key', sections: {', '.join(SECTIONS)})"
    raise ParameterError(f"unknown parameter {key!r}{hint}")


def _did_you_mean(name: str, known) -> str:
    """`` (did you mean 'X'?)`` for the known name nearest a misspelt one (case ignored:
    ``cd_c`` finds ``Cdc``), or an empty string."""
    lower = {k.lower(): k for k in known}
    close = difflib.get_close_matches(name.lower(), list(lower), 1)
    return f" (did you mean {lower[close[0]]!r}?)" if close else ""


def apply_overrides(p: Params, overrides: dict[str, Any]) -> Params:
    """Replace single values by dotted name (``"tether.length"``), with the same checks as loading."""
    if not isinstance(overrides, Mapping):
        raise ParameterError("overrides must map dotted parameter names to values, e.g. "
                             f"{{'tether.length': 300.0}}; got {overrides!r}")
    data = params_to_dict(p)
    for key, value in overrides.items():
        sec, name = parameter_key(data, key)
        data[sec][name] = list(value) if isinstance(value, tuple) else value
    new = params_from_dict(data)
    prov = dict(p.provenance)
    prov.update({key: USER for key in overrides})
    return dataclasses.replace(new, provenance=tuple(sorted(prov.items())))


BASELINE_NAME = "aeros_flightcam"


def shipped_configs() -> tuple[str, ...]:
    """Names of the parameter files shipped in aerostat_gym/data (loadable by name)."""
    data = resources.files("aerostat_gym").joinpath("data")
    return tuple(sorted(f.name[:-5] for f in data.iterdir() if f.name.endswith(".toml")))


def _config_text(path: str | Path | None) -> tuple[str, str]:
    """(TOML text, source name) of a path, a shipped configuration's name, or the baseline."""
    if path is None:
        path = BASELINE_NAME
    if isinstance(path, Params):
        raise ParameterError("load_params takes a TOML path or a shipped configuration's name, "
                             "got a Params (already loaded: use it, or .replace(...) for changes)")
    if not isinstance(path, (str, os.PathLike)):
        raise ParameterError(f"load_params takes a TOML path or a shipped configuration's name "
                             f"({', '.join(shipped_configs())}), got {type(path).__name__}"
                             + ("; for a dict of sections use params_from_dict"
                                if isinstance(path, dict) else ""))
    if not Path(path).is_file() and str(path) in shipped_configs():
        return resources.files("aerostat_gym").joinpath(f"data/{path}.toml").read_text(), str(path)
    path = Path(path)
    if path.is_dir():
        raise ParameterError(f"{path} is a folder: give a parameter file (.toml) in it, or a "
                             f"shipped configuration ({', '.join(shipped_configs())})")
    if not path.is_file():
        raise ParameterError(f"parameter file not found: {path} (shipped configurations: "
                             f"{', '.join(shipped_configs())})")
    try:  # TOML is UTF-8 by its specification, whatever the machine's locale
        # utf-8-sig: a byte-order mark (Windows editors write one) is dropped, not parsed
        return path.read_bytes().decode("utf-8-sig"), str(path)
    except UnicodeDecodeError as exc:
        raise ParameterError(f"{path}: not UTF-8 text (TOML files are UTF-8): byte "
                             f"{exc.object[exc.start]:#04x} at offset {exc.start}") from None
    except OSError as exc:
        raise ParameterError(f"{path}: cannot be read: {exc.strerror}") from None


def load_params(path: str | Path | None = None, overrides: dict[str, Any] | None = None) -> Params:
    """Load parameters from a TOML file, or a shipped configuration by name (``"tcom_32m"``;
    default: the baseline), and apply overrides."""
    text, source = _config_text(path)
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ParameterError(f"{source}: invalid TOML: {exc}") from exc
    p = params_from_dict(data)
    p = dataclasses.replace(p, provenance=tuple(sorted(status_comments(text).items())))
    p = apply_overrides(p, overrides) if overrides else p
    check_plausibility(p)
    _advise(p, source)
    for slip in status_slips(text):
        warnings.warn(f"{source}: {slip}", ParameterWarning, stacklevel=2)
    return p


def as_params(p: Params | str | Path | None, error: type[ValueError] = ParameterError) -> Params:
    """Parameters given as a Params, a TOML path or a shipped configuration's name, or None
    (the baseline); anything else is ``error`` naming its type. One door for the environment
    and the controllers' designs."""
    if p is None or isinstance(p, (str, os.PathLike)):
        return load_params(p)
    if not isinstance(p, Params):
        raise error(f"params must be a Params, a TOML path or None, got {type(p).__name__}")
    return validated(p)


def validated(p: Params) -> Params:
    """``p`` after the loader's field and cross checks: a Params built with
    ``dataclasses.replace`` (rather than :meth:`Params.replace`) skips them, and a zero
    element count or a string for g would otherwise fail deep in the model."""
    params_from_dict(params_to_dict(p))
    return p


STATUSES = ("SOURCED", "DERIVED", "ESTIMATE", "CALIB", "USER")
USER = "USER"


def status_comments(text: str) -> dict[str, str]:
    """The status word (SOURCED, DERIVED, ESTIMATE, CALIB or USER) of every ``key = value  #
    ... STATUS ...`` line of a parameter TOML, as {"section.key": status}; fin panels are named
    ``fins.panels[i].key``."""
    out, section, panel = {}, "", -1
    for line in text.splitlines():
        body = line.split("#", 1)[0].strip()
        if body.startswith("[[fins.panels]]"):
            panel += 1
            section = f"fins.panels[{panel}]"
            continue
        if body.startswith("["):
            section = body.strip("[]").strip()
            continue
        if "=" not in body or "#" not in line:
            continue
        comment = line.split("#", 1)[1]
        found = [w.strip("(),:;") for w in comment.split() if w.strip("(),:;") in STATUSES]
        if found:
            out[f"{section}.{body.split('=', 1)[0].strip()}"] = found[0]
    return out


def status_slips(text: str) -> list[str]:
    """A warning text for every parameter line whose comment has no status word but a word
    close to one (``SORCED``, ``ESTIMATED``, ``CALIBRATED``): the value would silently keep
    the baseline's status, or USER."""
    out = []
    for number, line in enumerate(text.splitlines(), 1):
        body, _, comment = line.partition("#")
        if "=" not in body or not comment:
            continue
        words = [w.strip("(),:;.") for w in comment.split()]
        if any(w in STATUSES for w in words):
            continue
        for w in (w for w in words if len(w) >= 4 and w.isupper()):
            near = [s for s in STATUSES
                    if w.startswith(s) or difflib.SequenceMatcher(None, w, s).ratio() >= 0.75]
            if near:
                out.append(f"line {number}: {w!r} is no status word (did you mean {near[0]!r}? "
                           f"one of {', '.join(STATUSES)}); "
                           f"{body.split('=', 1)[0].strip()} takes the baseline's status (USER "
                           "where its value differs)")
                break
    return out


def default_params(**overrides: Any) -> Params:
    """The baseline case; keyword overrides use ``__`` for the dot: ``tether__length=150``."""
    return load_params(overrides={k.replace("__", "."): v for k, v in overrides.items()} or None)


def dumps_toml(p: Params) -> str:
    """Serialise the inputs to TOML (used to store the resolved parameters of every run)."""

    def fmt(v: Any) -> str:
        if isinstance(v, str):
            return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
        if isinstance(v, bool):
            return "true" if v else "false"
        if isinstance(v, (list, tuple)):
            return "[" + ", ".join(fmt(x) for x in v) + "]"
        return repr(v)

    data = params_to_dict(p)
    lines = []
    for sec, table in data.items():
        lines.append(f"[{sec}]")
        for k, v in table.items():
            if k != "panels":
                lines.append(f"{k} = {fmt(v)}")
        lines.append("")
        if sec == "fins":
            for pan in table["panels"]:
                lines.append("[[fins.panels]]")
                lines.extend(f"{k} = {fmt(v)}" for k, v in pan.items())
                lines.append("")
    return "\n".join(lines)


def parameter_table(p: Params | None = None) -> list[dict]:
    """Rows (name, value, unit, status, description) of every input, for reports and the CLI.

    The status follows the value: the status comment of the user's own file where it has one
    (:attr:`Params.provenance`), USER for a value set by an override or one that differs from
    the shipped baseline without a comment, and the baseline's status (dataclass metadata)
    for a value equal to the baseline's.
    """
    p = p or load_params()
    base = _baseline_values()
    prov = dict(p.provenance)
    rows = _raw_rows(p)
    for r in rows:
        r["status"] = _status(r, prov, base)
    return rows


def _status(row: dict, provenance: dict, baseline: dict) -> str:
    name = row["name"]
    stated = provenance.get(name) or provenance.get(name.split(".panels[")[0] + ".panels")
    if stated is not None:
        return stated
    return row["status"] if baseline.get(name) == row["value"] else USER


def _baseline_values() -> dict:
    """{name: value} of the shipped baseline (parsed once)."""
    if not _BASELINE_VALUES:
        text, _ = _config_text(BASELINE_NAME)
        base = params_from_dict(tomllib.loads(text))
        _BASELINE_VALUES.update({r["name"]: r["value"] for r in _raw_rows(base)})
    return _BASELINE_VALUES


_BASELINE_VALUES: dict = {}


def _raw_rows(p: Params) -> list[dict]:
    rows = []
    for sec in SECTIONS:
        obj = getattr(p, sec)
        for f in fields(obj):
            if f.name == "panels":
                for i, pan in enumerate(obj.panels):
                    rows.extend(_row(f"fins.panels[{i}].{g.name}", getattr(pan, g.name), g)
                                for g in fields(pan))
            else:
                rows.append(_row(f"{sec}.{f.name}", getattr(obj, f.name), f))
    return rows


def _row(name: str, value: Any, f: dataclasses.Field) -> dict:
    m = f.metadata
    return {"name": name, "value": value, "unit": m["unit"], "status": m["status"], "description": m["doc"]}


# --- derived quantities --------------------------------------------------------------------------


@dataclass(frozen=True)
class Derived:
    """Quantities computed from the inputs ([LN02] and docs/parameters.md, section 4).

    Notes
    -----
    - buoyancy B = rho g V; net lift B - m g.
    - leash x_l from the zero-wind moment balance about the CM at trim pitch theta_0:
      B (x_b cos th + z_b sin th) = (B - m g)(x_l cos th + z_l sin th).
    - EA = E pi d^2 / 4; mu = rho_t A; element mass mu l_u, l_u = L / n.
    - b_c = 2 sqrt(EA m_el l_u) = 2 l_u A sqrt(E rho_t); b = zeta b_c. Because b is proportional
      to l_u, the element dashpot c* = b / l_u (force per unit of relative axial speed) does not
      depend on the element length; it is what the compiled core uses.
    - added masses m_a = k rho V per axis; effective masses m_e = m + m_a.
    - fin C_D,max = 1.11 + 0.018 A, the deep-stall drag (normal force at 90 deg) of a plate of
      aspect ratio A (Viterna & Corrigan 1982, "Fixed pitch rotor performance of large
      horizontal axis wind turbines", NASA CP-2230; the AirfoilPrep / WISDEM extrapolation).
    """

    buoyancy: float
    net_lift: float
    leash_position: tuple
    EA: float
    tether_area: float
    mass_per_length: float
    element_length: float
    element_mass: float
    critical_damping: float
    damping_b: float
    dashpot: float
    added_mass: tuple
    effective_mass: tuple
    tether_weight: float
    reference_area: float
    fin_cd_max: float

    @classmethod
    def from_params(cls, p: Params) -> Derived:
        env, a, t = p.environment, p.aerostat, p.tether
        B = env.rho_air * env.g * a.volume
        F_lz = B - a.mass * env.g
        th = math.radians(a.trim_pitch_deg)
        xb, _, zb = a.cb_position
        zl = a.leash_z
        x_l = (B * (xb + zb * math.tan(th)) - F_lz * zl * math.tan(th)) / F_lz if F_lz > 0 else float("nan")
        try:
            area = math.pi * t.diameter**2 / 4.0
        except OverflowError:  # a diameter past 1e154 m: the cross checks refuse its weight
            area = math.inf
        mu = t.density * area
        l_u = t.length / t.n_elements
        EA = t.youngs_modulus * area
        b_c = 2.0 * l_u * area * math.sqrt(t.youngs_modulus * t.density)
        ma = (a.k1 * env.rho_air * a.volume, a.k3 * env.rho_air * a.volume, a.k3 * env.rho_air * a.volume)
        return cls(
            buoyancy=B,
            net_lift=F_lz,
            leash_position=(x_l, 0.0, zl),
            EA=EA,
            tether_area=area,
            mass_per_length=mu,
            element_length=l_u,
            element_mass=mu * l_u,
            critical_damping=b_c,
            damping_b=t.damping_ratio * b_c,
            # b / l_u written without l_u, so that it is bitwise independent of the length
            dashpot=t.damping_ratio * 2.0 * area * math.sqrt(t.youngs_modulus * t.density),
            added_mass=ma,
            effective_mass=tuple(a.mass + m for m in ma),
            tether_weight=mu * t.length * env.g,
            reference_area=a.volume ** (2.0 / 3.0),
            fin_cd_max=1.11 + 0.018 * p.fins.aspect_ratio,
        )
