"""The parameter schema: one frozen dataclass per component, each field with its unit, the
baseline value's status (SOURCED, DERIVED, ESTIMATE, CALIB), the check its values must pass
and a description; the sections of a parameter file; the words it may use."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Any

import numpy as np


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
    rho_air: float = _f("kg/m^3", "DERIVED", POSITIVE,
                        "air density (baseline: the Table 2 fit, Option A)")
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
    CL_alpha: float = _f("1/rad", "CALIB", NONNEG, "3-D lift slope incl. hull interference loss "
                         "(baseline: calibrated, 0.68 x McCormick, to the 67.4 s lateral "
                         "pendulum)")
    alpha_stall_deg: float = _f("deg", "CALIB", STALL, "3-D stall angle of the low-aspect-ratio "
                                "fin (linear C_L below it) (baseline: calibrated to a restoring "
                                "static yaw moment at every yaw offset to 90 deg)")
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

#: The words a file may give for the enumerated fields (checked by
#: :mod:`aerostat_gym.params.constraints`).
WIND_PROFILES = ("uniform", "power", "log")
TURBULENCE_PRESETS = ("none", "light", "moderate", "severe")
TURBULENCE_MODELS = ("von_karman", "dryden")
POST_STALL_MODELS = ("viterna", "flat")

#: The status words of a value's provenance in a file's comments; USER marks a value the user
#: set (an override, or a value that differs from the baseline without a comment).
STATUSES = ("SOURCED", "DERIVED", "ESTIMATE", "CALIB", "USER")
USER = "USER"
