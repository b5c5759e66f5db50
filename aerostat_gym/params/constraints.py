"""Constraints between fields, checked on every load, override and replace: the enumerated
words, the winch's limits, the inertia tensor, the feasibility of lifting and holding the
tether, the compiled core's and the model's limits."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from .plausible import check_ranges, slip_hint
from .schema import (
    POST_STALL_MODELS,
    TURBULENCE_MODELS,
    TURBULENCE_PRESETS,
    WIND_PROFILES,
    ParameterError,
)

#: Largest number of fin panels: the compiled core packs the panels into a fixed-size block
#: (aerostat_gym.physics.packing.MAX_FINS is this constant; params sits below the physics
#: layer, so the core imports it from aerostat_gym.params).
MAX_FIN_PANELS = 6
#: [m/s] the fastest mean wind the model is defined for (every door checks this one): the
#: aerodynamics are incompressible (one air density everywhere), valid below Mach 0.3, about
#: 100 m/s at sea level. Tethered aerostats are flown far below it (the baseline's tether breaks at trim near
#: 60 m/s). README "Guarantees": a faster mean wind is refused.
MAX_WIND_SPEED = 100.0

if TYPE_CHECKING:  # annotations only: not imported at run time
    from .derived import Derived
    from .model import Params


def check_constraints(p: Params) -> None:
    """Constraints between fields, checked after every load or override (after the ranges of
    single values no aerostat leaves, which the constraints' messages would otherwise print)."""
    check_ranges(p)
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
    d = p.derived
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
            + slip_hint(p.wind.speed, {"km/h written as m/s": 1 / 3.6}, lambda v: v <= MAX_WIND_SPEED))
    z0 = p.tether.anchor_position[2]
    if z0 < 0.0:
        raise ParameterError(
            f"tether.anchor_position = {list(p.tether.anchor_position)} puts the winch at "
            f"z = {z0:g} m, below the ground (z = 0): its z must be >= 0 (the wind profile and "
            "the ground strike read heights above the ground)")


def check_length_within_winch(p: Params) -> None:
    """The paid-out tether length must lie inside the winch's length limits: beyond
    winch.max_length the drum would hold a negative length of line (and negative mass)."""
    L, w = p.tether.length, p.winch
    if not w.min_length <= L <= w.max_length:
        raise ParameterError(
            f"tether.length = {L} m lies outside the winch's limits winch.min_length = "
            f"{w.min_length} m .. winch.max_length = {w.max_length} m")
