"""Quantities that follow from the inputs (buoyancy, net lift, leash x_l, EA, element mass,
tether damping, added masses): computed, never typed in."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

if TYPE_CHECKING:  # annotations only: not imported at run time
    from .model import Params


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


def paid_out_weight(p: Params, length: float | None = None) -> float:
    """Weight [N] of ``length`` metres of tether (default ``tether.length``: the derived
    ``tether_weight``)."""
    return p.derived.mass_per_length * (p.tether.length if length is None else length) \
        * p.environment.g
