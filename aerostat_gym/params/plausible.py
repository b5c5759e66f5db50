"""Plausibility: values that pass their own field's check but no real aerostat has (refused,
most often a unit slip) or few have (warned).

A unit slip (MPa written as Pa, cm as m) passes every per-field check and the feasibility
checks, loads, and then fails every episode at step 0 far from its cause. The bounds below are
refused at the door (:func:`check_plausibility`, run by load_params on the file and its overrides
alike, and by the environment when it is made); values that are unusual but possible only warn
(:func:`plausibility_warnings`, a ParameterWarning). Every bound is generous: aerostats from 5 m
to 70 m hulls, tethers from 20 m to 5 km of Dyneema, Kevlar, Vectran, polyester or steel-armoured
conductor cable all pass. They are not checked by Params.replace / apply_overrides, so that
studies may still move one value past them on purpose (a weightless tether, RK4 past its
stability bound) in the simulator; the exception is :data:`PLAUSIBLE_RANGES`, single values
no aerostat on any planet has, which every load, override and replace checks
(:func:`aerostat_gym.params.constraints.check_constraints`).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from .derived import paid_out_weight
from .schema import FinPanel, ParameterError
from .steps import advised_semi_implicit_dt

if TYPE_CHECKING:  # annotations only: not imported at run time
    from .model import Params


class ImplausibleParameterError(ParameterError):
    """A value that passes its field's own check but no real aerostat or tether has, most often
    a unit slip; the message names the field, the value, the bound and the likely slip."""


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
#: aerostat.mass / (environment.rho_air * aerostat.volume), the total mass (lifting gas and
#: ballonet air included, as aerostat.mass means) per mass of the air the hull displaces. The
#: lifting gas alone weighs its molar mass over the air's times rho_air V at equal pressure and
#: temperature (a superpressure makes it heavier): hydrogen 2.016 / 28.97 = 0.070, helium
#: 4.003 / 28.97 = 0.138; envelope, fins and payload bring aerostats to 0.4-0.8 (the baseline
#: and the 32 m class 0.547). Below MIN the aerostat weighs less than hydrogen filling its hull
#: (1 g on the baseline's 519 m^3, or a mass in tonnes: 0.33 is 5.5e-4); below WARN less than
#: helium and a light envelope. The upper end, a positive net lift (ratio < 1), is refused on
#: every load, override and replace (constraints.check_constraints).
AEROSTAT_MASS_RATIO_MIN, AEROSTAT_MASS_RATIO_WARN = 0.05, 0.25
#: Radii of gyration k = sqrt(I / aerostat.mass) of the body's own moments of inertia (hull,
#: gases, fins and payload; the added masses k1, k3 are apart), roll k_x against
#: aerostat.diameter D, pitch and yaw k_y, k_z against aerostat.length L. The lifting gas is at
#: least 7 % of the mass (hydrogen's 0.070 rho_air V, against a mass below rho_air V) and fills
#: the hull, so even in a double cone (the thinnest hull: prismatic 1/3) it alone gives
#: k_x >= sqrt(0.07 * 0.075) D = 0.072 D and k_y, k_z >= sqrt(0.07 / 40) L = 0.042 L (helium,
#: 0.138: 0.10 D and 0.059 L); an envelope shell at D / 2 raises them to the aerostats' 0.3-0.45 D
#: and 0.2-0.3 L (baseline and 32 m class: k_x 0.40 D, k_y 0.26 L, k_z 0.26 L). Above: a
#: radius of gyration is at most the farthest mass's distance, and mass spread over a span s
#: has k <= s / 2 (Popoviciu's inequality): the hull gives k_x <= D / 2 and k_y, k_z <= about
#: L / 2, fins reach up to 2 D off the axis (FIN_RADIUS_MAX) and 0.25 L aft of the tail.
#: Refused: k_x outside 0.02-2 D, k_y or k_z outside 0.02-1 L (an inertia in g m^2, or in
#: t m^2, is 1000 times off: k 31.6 times; on the baseline k_x 12.7 D or 0.013 D); warning:
#: k_x outside 0.1-0.75 D (half again a thin shell's 0.5 D), k_y or k_z outside 0.06-0.5 L
#: (0.5 L: all mass at the hull's two ends). The lower refusals stay below the ends of a
#: +-90 % inertia randomisation (0.1 x the moments: 0.32 k) of a needle-like hull
#: (tests/test_reliability.py: Ixx 200 kg m^2 on the baseline, k_x 0.032 D at that end).
GYRATION_ROLL_MAX, GYRATION_ROLL_WARN = (0.02, 2.0), (0.1, 0.75)
GYRATION_PITCH_MAX, GYRATION_PITCH_WARN = (0.02, 1.0), (0.06, 0.5)
#: aerostat.trim_pitch_deg (negative = nose up), the zero-wind trim pitch that fixes the leash
#: point: [LN02] quotes a manufacturer's 5-10 deg nose up and flies 4 deg (the shipped files
#: -4, the generated aerostats -6..0). Outside WARN (more than 20 deg nose up or 10 deg nose
#: down in still air) no aerostat is rigged: at 60 deg the baseline trims 21 deg nose down with
#: 37 deg of blow-by at 10 m/s. The field's own check refuses |pitch| >= 89 deg.
TRIM_PITCH_WARN = (-20.0, 10.0)
#: wind.shear_exponent of the power profile U (z / z_ref)^alpha, fitted to atmospheric boundary
#: layers: 0.06-0.1 over open sea and in unstable air, 1/7 over open land in neutral air,
#: 0.25-0.4 over suburbs and cities, up to about 0.6 in very stable nights over rough land
#: (the Hellmann-exponent tables of wind-energy texts). Above WARN only such nights, in light
#: wind; above MAX no boundary layer (1: linear growth; 0.6 already takes 10 m/s at 10 m to
#: 77 m/s at 300 m, 3 to 2.7e5 m/s). Checked where wind.profile = "power".
SHEAR_EXPONENT_WARN, SHEAR_EXPONENT_MAX = 0.5, 1.0
#: [m] wind.roughness_length z0 of the log profile U ln(z / z0) / ln(z_ref / z0): from about
#: 1e-5 m over calm sea and 0.03-0.1 m over grass and crops to 1-2 m over city centres
#: (Wieringa 1992, J. Wind Eng. Ind. Aerodyn. 41, the Davenport classes: "chaotic" high-rise
#: centres >= 2 m; measured values up to about 3 m). Above WARN only high-rise centres (or
#: 2-5 cm written as m); above MAX no terrain (9 m takes 10 m/s at 10 m to 330 m/s at 300 m).
#: Checked where wind.profile = "log" (constraints also refuse z0 >= z_ref on every door).
ROUGHNESS_LENGTH_WARN, ROUGHNESS_LENGTH_MAX = 2.0, 5.0
#: wind.turbulence_reference_height more than this factor from tether.length warns at load
TURBULENCE_HEIGHT_WARN = 1.5


def slip_hint(value: float, factors: dict[str, float], ok) -> str:
    """``; looks like <slip>`` for the first unit slip whose correction factor makes ``ok``
    true, or an empty string."""
    for text, factor in factors.items():
        if ok(value * factor):
            return f"; looks like {text}"
    return ""


def safe_ratio(a: float, b: float) -> float:
    """a / b for a >= 0, b >= 0 that underflowed or overflowed: inf where b is 0 (a bound then
    refuses it instead of a ZeroDivisionError)."""
    return a / b if b > 0.0 else math.inf


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


def check_ranges(p: Params) -> None:
    """:data:`PLAUSIBLE_RANGES`, each an ImplausibleParameterError naming the field, with the
    likely slip of a percentage where a hundredth of the value is in range."""
    for key, (low, high, usual) in PLAUSIBLE_RANGES.items():
        section, name = key.split(".")
        value = getattr(getattr(p, section), name)
        if not low <= value <= high:
            raise ImplausibleParameterError(
                f"{key} = {value:g} lies outside [{low:g}, {high:g}] ({usual})"
                + slip_hint(value, {"a percentage written as a fraction": 0.01},
                        lambda v, lo=low, hi=high: lo <= v <= hi))


def check_plausibility(p: Params) -> None:
    """Refuse values that load but no real aerostat has (:class:`ImplausibleParameterError`),
    naming the field, the value, the bound and the likely slip. Run by :func:`load_params` and
    when an environment is made (:data:`PLAUSIBLE_RANGES` on every load and replace too)."""
    _plausible_tether(p)
    _plausible_hull(p)
    _plausible_mass(p)
    _plausible_wind(p)
    _plausible_body_points(p)
    _plausible_numerics(p)


def _plausible_tether(p: Params) -> None:
    """The tether's stiffness (its stretch under its own breaking strength and under the net
    lift) and its effective density."""
    t, d = p.tether, p.derived
    E = t.youngs_modulus
    break_strain, lift_strain = safe_ratio(t.strength, d.EA), safe_ratio(d.net_lift, d.EA)
    if E > TETHER_MODULUS_MAX:
        raise ImplausibleParameterError(
            f"tether.youngs_modulus = {E:g} Pa exceeds {TETHER_MODULUS_MAX:g} Pa, stiffer than "
            "diamond" + slip_hint(E, {"kPa written as Pa": 1e-3, "MPa written as Pa": 1e-6},
                              lambda v: v <= TETHER_MODULUS_MAX))
    if break_strain > TETHER_BREAK_STRAIN_MAX or lift_strain > TETHER_LIFT_STRAIN_MAX:
        ok = lambda v: (v <= TETHER_MODULUS_MAX  # noqa: E731
                        and safe_ratio(t.strength, v * d.tether_area) <= TETHER_BREAK_STRAIN_WARN
                        and safe_ratio(d.net_lift, v * d.tether_area) <= TETHER_LIFT_STRAIN_MAX)
        hint = slip_hint(E, {"MPa written as Pa": 1e6, "GPa written as Pa": 1e9,
                             "GPa written as MPa": 1e3}, ok)
        if not hint and lift_strain <= TETHER_LIFT_STRAIN_MAX:
            # the modulus holds the net lift: the strength does not belong to this line
            hint = (f"; if the modulus is right, tether.strength does not fit tether.diameter: "
                    f"this line would stretch {100 * TETHER_BREAK_STRAIN_WARN:g} % at "
                    f"{TETHER_BREAK_STRAIN_WARN * d.EA:.4g} N")
        raise ImplausibleParameterError(
            f"tether.youngs_modulus = {E:g} Pa gives EA = {d.EA:.4g} N on the "
            f"{1000 * t.diameter:g} mm tether (tether.diameter): it would stretch by "
            f"{100 * lift_strain:.3g} % under the net lift ({d.net_lift:.1f} N) and by "
            f"{100 * break_strain:.3g} % at tether.strength ({t.strength:g} N); a real tether "
            f"stretches a few % at break (bounds: {100 * TETHER_LIFT_STRAIN_MAX:g} % under the "
            f"net lift, {100 * TETHER_BREAK_STRAIN_MAX:g} % at break)" + hint)
    rho_t = t.density
    lo, hi = TETHER_DENSITY_MAX
    if not lo <= rho_t <= hi:
        raise ImplausibleParameterError(
            f"tether.density = {rho_t:g} kg/m^3 (a {1000 * d.mass_per_length:.4g} g/m line at "
            f"tether.diameter = {1000 * t.diameter:g} mm) lies outside [{lo:g}, {hi:g}] kg/m^3, "
            "the effective density of any rope or cable (it is the material density, kg/m^3, "
            "not the mass per length)"
            + slip_hint(rho_t, {"g/cm^3 written as kg/m^3": 1e3, "kg/m (mass per length) written "
                            "as kg/m^3": 1.0 / d.tether_area}, lambda v: lo <= v <= hi))


def _plausible_hull(p: Params) -> None:
    """Length, diameter and volume must describe one body."""
    a = p.aerostat
    cyl = math.pi / 4.0 * a.diameter * a.diameter * a.length  # inf, not OverflowError
    prismatic, fineness = safe_ratio(a.volume, cyl), safe_ratio(a.length, a.diameter)
    lo, hi = HULL_PRISMATIC_MAX
    if not lo <= prismatic <= hi:
        raise ImplausibleParameterError(
            f"aerostat.volume = {a.volume:g} m^3 is {prismatic:.3g} times the cylinder "
            f"pi d^2 L / 4 = {cyl:.4g} m^3 enclosing aerostat.length = {a.length:g} m and "
            f"aerostat.diameter = {a.diameter:g} m; a hull fills {lo:g}..{hi:g} of it "
            "(streamlined hulls 0.55-0.7)"
            + slip_hint(prismatic, {"aerostat.diameter in cm": 1e4, "aerostat.length in cm": 1e2,
                                "aerostat.diameter in mm": 1e6, "aerostat.volume in litres": 1e-3,
                                "aerostat.diameter written as the radius": 0.25},
                    lambda v: lo <= v <= hi))
    if not HULL_FINENESS_MIN <= fineness <= HULL_FINENESS_MAX:
        raise ImplausibleParameterError(
            f"aerostat.length / aerostat.diameter = {a.length:g} / {a.diameter:g} = "
            f"{fineness:.3g} lies outside [{HULL_FINENESS_MIN:g}, {HULL_FINENESS_MAX:g}] (a "
            "sphere has 1, aerostats 2.2-4, the slimmest airships about 8)"
            + ("; looks like length and diameter swapped" if fineness < 1 else ""))


def mass_ratio(p: Params) -> float:
    """aerostat.mass / (environment.rho_air * aerostat.volume): the total mass per mass of air
    displaced (:data:`AEROSTAT_MASS_RATIO_MIN`)."""
    return safe_ratio(p.aerostat.mass, p.environment.rho_air * p.aerostat.volume)


def gyration_radii(p: Params) -> list[tuple[str, float, float, str, tuple, tuple]]:
    """(field, moment, radius of gyration sqrt(I / mass) over its reference length, the
    reference's name, refused bounds, warning bounds) of Ixx (against the diameter), Iyy and
    Izz (against the length)."""
    a = p.aerostat
    out = []
    for name, ref, ref_name, refuse, warn in (
            ("Ixx", a.diameter, "aerostat.diameter", GYRATION_ROLL_MAX, GYRATION_ROLL_WARN),
            ("Iyy", a.length, "aerostat.length", GYRATION_PITCH_MAX, GYRATION_PITCH_WARN),
            ("Izz", a.length, "aerostat.length", GYRATION_PITCH_MAX, GYRATION_PITCH_WARN)):
        moment = getattr(a, name)
        out.append((f"aerostat.{name}", moment, safe_ratio(math.sqrt(moment / a.mass), ref),
                    ref_name, refuse, warn))
    return out


def _plausible_mass(p: Params) -> None:
    """The mass against the air the hull displaces, and the radii of gyration against the
    hull's diameter and length (unit slips of tonnes, g m^2, t m^2)."""
    a = p.aerostat
    displaced = p.environment.rho_air * a.volume
    ratio, lo = mass_ratio(p), AEROSTAT_MASS_RATIO_MIN
    if ratio < lo:
        raise ImplausibleParameterError(
            f"aerostat.mass = {a.mass:g} kg is {ratio:.3g} of the {displaced:.4g} kg of air the "
            f"hull displaces (environment.rho_air * aerostat.volume), below {lo:g}: the mass "
            "includes the lifting gas, which alone weighs 0.070 (hydrogen) to 0.138 (helium) "
            "of it; aerostats weigh 0.4-0.8 of it"
            + slip_hint(a.mass, {"tonnes written as kg": 1e3},
                        lambda v: lo <= safe_ratio(v, displaced) < 1.0))
    for key, moment, k, ref_name, (low, high), _ in gyration_radii(p):
        if low <= k <= high:
            continue
        ref = getattr(a, ref_name.split(".")[1])
        ok = lambda v, r=ref, lo_=low, hi=high: lo_ <= math.sqrt(v / a.mass) / r <= hi  # noqa: E731
        raise ImplausibleParameterError(
            f"{key} = {moment:g} kg m^2 gives a radius of gyration sqrt({key} / aerostat.mass) "
            f"= {k * ref:.4g} m, {k:.3g} x {ref_name} = {ref:g} m, outside [{low:g}, {high:g}] "
            f"x {ref_name} (aerostats {'0.3-0.45' if key.endswith('Ixx') else '0.2-0.3'}; "
            "the lifting gas alone gives more than the lower bound, and no mass lies far enough "
            "off the hull for the upper)"
            + slip_hint(moment, {"g m^2 written as kg m^2": 1e-3, "t m^2 written as kg m^2": 1e3,
                                 "kg cm^2 written as kg m^2": 1e-4}, ok))


def profile_factor(p: Params, height: float) -> float:
    """The configured mean profile's speed at ``height`` metres above the ground over its speed
    at wind.reference_height (1 for the uniform profile)."""
    w = p.wind
    z = max(height, w.roughness_length * 1.01, 0.5)  # the core's lowest height (W_ZMIN)
    if w.profile == "power":
        exponent = w.shear_exponent * math.log(z / w.reference_height)
        return math.exp(min(exponent, 700.0))  # inf-like, not OverflowError, past 1e304
    if w.profile == "log":
        return math.log(z / w.roughness_length) / math.log(w.reference_height / w.roughness_length)
    return 1.0


def _flight_factor(p: Params) -> str:
    """``: it takes ... at the aerostat's height`` for the wind profile's messages."""
    z = p.tether.anchor_position[2] + p.tether.length
    return (f"; it takes the reference speed {profile_factor(p, z):.3g}-fold to the aerostat's "
            f"height (about {z:g} m: tether.length above the winch)")


def _plausible_wind(p: Params) -> None:
    """The mean profile's shape: the power law's exponent and the log law's roughness length,
    where that profile is configured."""
    w = p.wind
    if w.profile == "power" and w.shear_exponent > SHEAR_EXPONENT_MAX:
        raise ImplausibleParameterError(
            f"wind.shear_exponent = {w.shear_exponent:g} exceeds {SHEAR_EXPONENT_MAX:g} for "
            "wind.profile = 'power': atmospheric boundary layers have 0.06-0.1 over the sea, "
            "1/7 over open land, 0.25-0.4 over cities and up to about 0.6 in very stable nights"
            + _flight_factor(p)
            + slip_hint(w.shear_exponent, {"a percentage written as a fraction": 0.01},
                        lambda v: 0.05 <= v <= SHEAR_EXPONENT_WARN))
    if w.profile == "log" and w.roughness_length > ROUGHNESS_LENGTH_MAX:
        raise ImplausibleParameterError(
            f"wind.roughness_length = {w.roughness_length:g} m exceeds "
            f"{ROUGHNESS_LENGTH_MAX:g} m for wind.profile = 'log': terrain has 1e-5 m (calm "
            "sea) to 0.1 m (crops), 1-2 m over city centres, about 3 m at most"
            + _flight_factor(p)
            + slip_hint(w.roughness_length, {"cm written as m": 0.01},
                        lambda v: v <= ROUGHNESS_LENGTH_MAX))


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
            + slip_hint(zl, {"cm written as m": 0.01}, lambda v: -v <= LEASH_DEPTH_MAX * L))


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


def plausibility_warnings(p: Params) -> list[str]:
    """Values that are unusual but possible (a ParameterWarning each at load)."""
    a, t, d = p.aerostat, p.tether, p.derived
    out = []
    strain = safe_ratio(t.strength, d.EA)
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
    prismatic = safe_ratio(a.volume, math.pi / 4.0 * a.diameter * a.diameter * a.length)
    if not lo <= prismatic <= hi:
        out.append(f"aerostat.volume = {a.volume:g} m^3 is {prismatic:.3g} of the cylinder "
                   "enclosing aerostat.length and aerostat.diameter (streamlined hulls: "
                   f"0.55-0.7; warning outside [{lo:g}, {hi:g}])")
    fineness = safe_ratio(a.length, a.diameter)
    if fineness > HULL_FINENESS_WARN:
        out.append(f"aerostat.length / aerostat.diameter = {fineness:.3g} is slimmer than any "
                   f"airship (warning above {HULL_FINENESS_WARN:g})")
    if p.hull.Cdc > HULL_CDC_WARN:
        out.append(f"hull.Cdc = {p.hull.Cdc:g} is above a circular cylinder's 0.3-1.2 "
                   f"(warning above {HULL_CDC_WARN:g})")
    out.extend(_mass_and_wind_warnings(p))
    out.extend(turbulence_height_warnings(p))
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


def _mass_and_wind_warnings(p: Params) -> list[str]:
    """Unusual mass, radii of gyration, trim pitch and wind profile (the bands inside the
    refusals of :func:`_plausible_mass` and :func:`_plausible_wind`)."""
    a, w = p.aerostat, p.wind
    out = []
    ratio = mass_ratio(p)
    if ratio < AEROSTAT_MASS_RATIO_WARN:
        out.append(f"aerostat.mass = {a.mass:g} kg is {ratio:.3g} of the air the hull displaces "
                   "(environment.rho_air * aerostat.volume): helium alone weighs 0.138 of it, "
                   "aerostats 0.4-0.8 (it is the total mass, lifting gas included; warning "
                   f"below {AEROSTAT_MASS_RATIO_WARN:g})")
    for key, moment, k, ref_name, _, (low, high) in gyration_radii(p):
        if not low <= k <= high:
            out.append(f"{key} = {moment:g} kg m^2 gives a radius of gyration of {k:.3g} x "
                       f"{ref_name} (sqrt({key} / aerostat.mass); aerostats "
                       f"{'0.3-0.45' if key.endswith('Ixx') else '0.2-0.3'}; warning outside "
                       f"[{low:g}, {high:g}])")
    lo, hi = TRIM_PITCH_WARN
    if not lo <= a.trim_pitch_deg <= hi:
        out.append(f"aerostat.trim_pitch_deg = {a.trim_pitch_deg:g} deg (negative = nose up) is "
                   "no aerostat's zero-wind trim: [LN02] quotes 5-10 deg nose up, the shipped "
                   f"files use -4 (warning outside [{lo:g}, {hi:g}] deg); it places the leash "
                   "point, and with it the attitude and blow-by in every wind")
    if w.profile == "power" and w.shear_exponent > SHEAR_EXPONENT_WARN:
        out.append(f"wind.shear_exponent = {w.shear_exponent:g} is steeper than any boundary "
                   "layer but a very stable night's (open land 1/7, cities 0.25-0.4; warning "
                   f"above {SHEAR_EXPONENT_WARN:g})" + _flight_factor(p))
    if w.profile == "log" and w.roughness_length > ROUGHNESS_LENGTH_WARN:
        out.append(f"wind.roughness_length = {w.roughness_length:g} m is rougher than any terrain "
                   "but a high-rise city centre (grass 0.03, suburbs 0.5, city centres 1-2 m; "
                   f"warning above {ROUGHNESS_LENGTH_WARN:g} m)" + _flight_factor(p)
                   + slip_hint(w.roughness_length, {"cm written as m": 0.01},
                               lambda v: v <= ROUGHNESS_LENGTH_WARN))
    return out


def turbulence_height_warnings(p: Params) -> list[str]:
    """The turbulence reference height far from the height the aerostat flies at (a factor
    :data:`TURBULENCE_HEIGHT_WARN` off the tether length): a list of one text, or empty."""
    ref, length = p.wind.turbulence_reference_height, p.tether.length
    if length / TURBULENCE_HEIGHT_WARN <= ref <= length * TURBULENCE_HEIGHT_WARN:
        return []
    return [f"wind.turbulence_reference_height = {ref:g} m is far from the aerostat's "
            f"height (tether.length = {length:g} m): the turbulence's intensity, length "
            f"scales and advection are those at {ref:g} m; set it near the height the "
            "aerostat flies at (the shipped files and scale_aerostat use the tether "
            f"length; warning outside a factor {TURBULENCE_HEIGHT_WARN:g} of it)"]


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
