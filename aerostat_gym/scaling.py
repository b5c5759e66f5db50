"""Geometrically similar aerostats: a parameter set scaled from another one.

A user with only a hull length and volume can start from the shipped aerostat scaled to that
size; the tests use it to generate aerostats of very different size, tether and length.
Geometric similarity with linear factor s = (V / V_0)^(1/3) and the same gas, fabric and air:

- lengths and body positions scale with s, areas (fins, I1, J1) with s^2, volumes (I3, J2) and
  masses with s^3, moments of inertia with s^5, dimensionless coefficients not at all;
- the net lift then scales with s^3, so the tether's cross-section is scaled with s^3 as well
  (same static stress and strain at the confluence point; diameter with s^1.5, strength with
  s^3), and the winch's force limits and drivetrain mass with s^3;
- the tether length is set independently; the winch's length limits keep their baseline
  proportions to it (min 0.5 L, max 4/3 L, line on the drum = max);
- the semi-implicit integration step shrinks with sqrt(s) for a smaller aerostat (Froude time
  scaling: the rigid-body time scales, whose explicitly integrated aerodynamics bound the step,
  shrink so) and is never lengthened for a larger one. Measured on 0.1 x the volume (100 m,
  6 elements), severe turbulence, 8-25 m/s, random winch commands, 40,000 steps: 8 episodes
  ended as ``numerical_divergence`` at the baseline's 50 ms, none at 34 ms.

The strength law holds the margin of the zero-wind load, not of the wind load: drag grows with
s^2 U^2 against a strength in s^3, so a scaled-down aerostat has less margin in strong wind.
Winch tension at the trim over tether strength at 0 / 15 / 25 / 35 m/s: baseline 0.07 / 0.11 /
0.21 / 0.38; volume x 0.1 on 100 m 0.07 / 0.17 / 0.42 / 0.82; volume x 10 on 1000 m 0.07 /
0.08 / 0.12 / 0.19 (``envs.batch.trim_table``). In a random-winch soak at 25-35 m/s the x 0.1
aerostat breaks its tether; check the strength of a scaled-down tether against your winds.
"""

from __future__ import annotations

from .checks import is_finite_number
from .params import (
    ParameterError,
    Params,
    froude_step,
    params_from_dict,
    params_to_dict,
    tether_drag_step,
)

#: Winch length limits as fractions of the nominal tether length (the baseline's 150 / 400 m
#: for 300 m).
WINCH_MIN_FRACTION = 0.5
WINCH_MAX_FRACTION = 4.0 / 3.0


def _scale_vec(v, s):
    return [float(c) * s for c in v]


def scale_aerostat(params: Params, volume_factor: float, tether_length: float,
                   n_elements: int | None = None, trim_pitch_deg: float | None = None) -> Params:
    """The aerostat of ``params`` scaled to ``volume_factor`` times its volume, on a tether of
    ``tether_length`` metres (see the module docstring for the laws).

    Parameters
    ----------
    params : Params
        The aerostat to scale.
    volume_factor : float
        V / V_0 (> 0).
    tether_length : float
        Tether length paid out [m] (> 0).
    n_elements : int, optional
        Tether elements (default: unchanged).
    trim_pitch_deg : float, optional
        Zero-wind trim pitch [deg] (default: unchanged); the leash point follows from it.

    Returns
    -------
    Params, validated like a loaded file.
    """
    if not (is_finite_number(volume_factor) and volume_factor > 0):
        raise ParameterError(f"volume_factor must be a finite number > 0, got {volume_factor!r}")
    if not (is_finite_number(tether_length) and tether_length > 0):
        raise ParameterError(f"tether_length must be a finite number > 0, got {tether_length!r}")
    s = volume_factor ** (1.0 / 3.0)
    d = params_to_dict(params)
    a, h, f, t, w = d["aerostat"], d["hull"], d["fins"], d["tether"], d["winch"]
    for key in ("length", "diameter", "leash_z"):
        a[key] *= s
    a["volume"] *= s**3
    a["mass"] *= s**3
    for key in ("Ixx", "Iyy", "Izz", "Ixz"):
        a[key] *= s**5
    a["cb_position"] = _scale_vec(a["cb_position"], s)
    a["nose_position"] = _scale_vec(a["nose_position"], s)
    h["l_h"] *= s
    h["I1"] *= s**2
    h["J1"] *= s**2
    h["I3"] *= s**3
    h["J2"] *= s**3
    f["planform_area"] *= s**2
    for pan in f["panels"]:
        pan["cp_position"] = _scale_vec(pan["cp_position"], s)
    t["diameter"] *= s**1.5
    t["strength"] *= s**3
    t["length"] = float(tether_length)
    for key in ("equivalent_mass", "coulomb_friction", "viscous_friction", "max_motor_force",
                "safe_working_load", "slack_tension"):
        w[key] *= s**3
    w["min_length"] = WINCH_MIN_FRACTION * tether_length
    w["max_length"] = WINCH_MAX_FRACTION * tether_length
    w["total_line_length"] = w["max_length"]
    d["wind"]["turbulence_reference_height"] = float(tether_length)
    # Froude time scaling, and no longer than the thinner line's explicit drag allows
    d["simulation"]["semi_implicit_dt"] = min(
        froude_step(d["simulation"]["semi_implicit_dt"], s),
        tether_drag_step(t["diameter"], t["density"], t["Cd_normal"],
                         d["environment"]["rho_air"]))
    if n_elements is not None:  # checked, like the trim pitch, as if typed into the file
        t["n_elements"] = n_elements
    if trim_pitch_deg is not None:
        a["trim_pitch_deg"] = trim_pitch_deg
    return params_from_dict(d)
