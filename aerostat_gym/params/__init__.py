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

One job per module, from the bottom up (each imports only those above it in this list):

- ``schema``: the component dataclasses, their fields' units, statuses and checks; the errors.
- ``fields``: one section of a file into its dataclass, each value against its field's check.
- ``derived``: :class:`Derived`, the quantities that follow from the inputs.
- ``steps``: the semi-implicit step advised for an aerostat.
- ``plausible``: values no real aerostat has (refused) or few have (warned).
- ``constraints``: constraints between fields, checked on every load, override and replace.
- ``model``: :class:`Params` and its conversions to and from dicts; overrides.
- ``files``: loading and writing parameter files; the status comments.
- ``table``: the parameter table with the status of every value.

Everything public is importable from ``aerostat_gym.params`` itself; the modules' other
names (``check_value``, ``config_text``, ...) serve the package's own modules.
"""

from .constraints import (
    MAX_FIN_PANELS,
    MAX_WIND_SPEED,
    InertiaError,
    check_inertia,
    check_length_within_winch,
    check_limits,
)
from .derived import Derived, paid_out_weight
from .files import (
    BASELINE_NAME,
    as_params,
    default_params,
    dumps_toml,
    load_params,
    shipped_configs,
    status_comments,
    status_slips,
)

# importable from here as before the split into modules (0.7.15 and earlier)
from .files import tomllib as tomllib
from .model import (
    Params,
    apply_overrides,
    parameter_key,
    params_from_dict,
    params_to_dict,
    validated,
)
from .plausible import (
    AEROSTAT_MASS_RATIO_MIN,
    AEROSTAT_MASS_RATIO_WARN,
    FIN_AFT_OF_TAIL,
    FIN_RADIUS_MAX,
    GYRATION_PITCH_MAX,
    GYRATION_PITCH_WARN,
    GYRATION_ROLL_MAX,
    GYRATION_ROLL_WARN,
    HULL_CDC_MAX,
    HULL_CDC_WARN,
    HULL_FINENESS_MAX,
    HULL_FINENESS_MIN,
    HULL_FINENESS_WARN,
    HULL_PRISMATIC_MAX,
    HULL_PRISMATIC_WARN,
    LEASH_DEPTH_MAX,
    PLAUSIBLE_RANGES,
    RK4_SAFETY_LIMIT,
    ROUGHNESS_LENGTH_MAX,
    ROUGHNESS_LENGTH_WARN,
    SEMI_IMPLICIT_REFUSE_FACTOR,
    SHEAR_EXPONENT_MAX,
    SHEAR_EXPONENT_WARN,
    TETHER_BREAK_STRAIN_MAX,
    TETHER_BREAK_STRAIN_WARN,
    TETHER_DENSITY_MAX,
    TETHER_DENSITY_WARN,
    TETHER_LIFT_STRAIN_MAX,
    TETHER_MODULUS_MAX,
    TRIM_PITCH_WARN,
    ImplausibleParameterError,
    check_plausibility,
    gyration_radii,
    hull_integral_warnings,
    mass_ratio,
    plausibility_warnings,
    profile_factor,
    turbulence_height_warnings,
)
from .schema import (
    ANY,
    BOOL,
    COEFFS,
    EFFICIENCY,
    FRACTION,
    INT_GE1,
    MAX_ELEMENTS,
    NONNEG,
    POSITIVE,
    POST_STALL_MODELS,
    SECTIONS,
    STALL,
    STATUSES,
    TURBULENCE_MODELS,
    TURBULENCE_PRESETS,
    USER,
    VEC3,
    WIND_PROFILES,
    AerostatParams,
    EnvironmentParams,
    FinPanel,
    FinParams,
    HullParams,
    ParameterError,
    ParameterWarning,
    SimulationParams,
    TetherParams,
    WinchParams,
    WindParams,
)
from .steps import (
    SEMI_IMPLICIT_REFERENCE_DT,
    SEMI_IMPLICIT_REFERENCE_HULL_LENGTH,
    TETHER_DRAG_REFERENCE_SPEED,
    advised_semi_implicit_dt,
    froude_step,
    tether_drag_step,
)
from .table import parameter_table

__all__ = [
    "AEROSTAT_MASS_RATIO_MIN", "AEROSTAT_MASS_RATIO_WARN", "GYRATION_PITCH_MAX",
    "GYRATION_PITCH_WARN", "GYRATION_ROLL_MAX", "GYRATION_ROLL_WARN", "ROUGHNESS_LENGTH_MAX",
    "ROUGHNESS_LENGTH_WARN", "SHEAR_EXPONENT_MAX", "SHEAR_EXPONENT_WARN", "TRIM_PITCH_WARN",
    "gyration_radii", "mass_ratio", "profile_factor",
    "ANY", "AerostatParams", "BASELINE_NAME", "BOOL", "COEFFS", "Derived", "EFFICIENCY",
    "EnvironmentParams", "FIN_AFT_OF_TAIL", "FIN_RADIUS_MAX", "FRACTION", "FinPanel", "FinParams",
    "HULL_CDC_MAX", "HULL_CDC_WARN", "HULL_FINENESS_MAX", "HULL_FINENESS_MIN",
    "HULL_FINENESS_WARN", "HULL_PRISMATIC_MAX", "HULL_PRISMATIC_WARN", "HullParams", "INT_GE1",
    "ImplausibleParameterError", "InertiaError", "LEASH_DEPTH_MAX", "MAX_ELEMENTS",
    "MAX_FIN_PANELS", "MAX_WIND_SPEED", "NONNEG", "PLAUSIBLE_RANGES", "POSITIVE",
    "POST_STALL_MODELS", "ParameterError", "ParameterWarning", "Params", "RK4_SAFETY_LIMIT",
    "SECTIONS", "SEMI_IMPLICIT_REFERENCE_DT", "SEMI_IMPLICIT_REFERENCE_HULL_LENGTH",
    "SEMI_IMPLICIT_REFUSE_FACTOR", "STALL", "STATUSES", "SimulationParams",
    "TETHER_BREAK_STRAIN_MAX", "TETHER_BREAK_STRAIN_WARN", "TETHER_DENSITY_MAX",
    "TETHER_DENSITY_WARN", "TETHER_DRAG_REFERENCE_SPEED", "TETHER_LIFT_STRAIN_MAX",
    "TETHER_MODULUS_MAX", "TURBULENCE_MODELS", "TURBULENCE_PRESETS", "TetherParams", "USER",
    "VEC3", "WIND_PROFILES", "WinchParams", "WindParams", "advised_semi_implicit_dt",
    "apply_overrides", "as_params", "check_inertia", "check_length_within_winch", "check_limits",
    "check_plausibility", "default_params", "dumps_toml", "froude_step", "hull_integral_warnings",
    "load_params", "paid_out_weight", "parameter_key", "parameter_table", "params_from_dict",
    "params_to_dict", "plausibility_warnings", "turbulence_height_warnings", "shipped_configs", "status_comments",
    "status_slips", "tether_drag_step", "validated",
]
