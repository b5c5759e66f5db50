"""The longest semi-implicit step advised for an aerostat: the baseline's measured step carried
to the hull by Froude scaling, bounded by the explicit tether drag's stability."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

if TYPE_CHECKING:  # annotations only: not imported at run time
    from .model import Params


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
