"""Episode outcomes of a control step, decided in one compiled place.

The environment's compiled step (:mod:`aerostat_gym.envs.kernel`) and the simulator's winch
events (:class:`aerostat_gym.sim.winch.WinchController`) both call these functions, so a tether
break, a ground strike or a length-limit excursion means the same thing in every front end.
"""

from __future__ import annotations

from numba import njit

from ..physics.core import FASTMATH
from ..physics.packing import P_NEL, P_STRENGTH, P_W_LMAX, P_W_LMIN
from ..physics.state import S_LENGTH, S_Z, aerostat_offset

#: Outcome codes of a control step.
RUNNING, NONFINITE, TETHER_BREAK, GROUND_STRIKE, LENGTH_LIMIT, FIELD_END = range(6)
#: Reason strings (``info["termination"]``, ``info["failure"]``, ``info["truncation"]``).
OUTCOMES = {NONFINITE: "nonfinite_state", TETHER_BREAK: "tether_break",
            GROUND_STRIKE: "ground_strike", LENGTH_LIMIT: "length_limit",
            FIELD_END: "wind_field_exhausted"}
#: [m] the winch's stopping profile keeps L inside its limits to much better than this.
LENGTH_TOL = 1e-3

_JIT = {"cache": True, "error_model": "numpy", "fastmath": FASTMATH}


@njit(**_JIT)
def tether_broken(peak_tension, strength):
    """An element tension above the tether's strength during the step breaks the tether."""
    return peak_tension > strength


@njit(**_JIT)
def step_outcome(x, t, p, peak_tension, ground_height, horizon):
    """Outcome code at the end of a control step ending at time t.

    peak_tension : largest element tension over the step [N]. ground_height : CM height below
    which the aerostat has struck the ground [m]. horizon : last time the turbulence field
    covers [s] (inf without turbulence). Checked in this order: break, ground strike, length
    outside the winch's limits, end of the wind field.
    """
    o = aerostat_offset(int(p[P_NEL]))
    if tether_broken(peak_tension, p[P_STRENGTH]):
        return TETHER_BREAK
    if x[o + S_Z] < ground_height:
        return GROUND_STRIKE
    L = x[o + S_LENGTH]
    if L < p[P_W_LMIN] - LENGTH_TOL or L > p[P_W_LMAX] + LENGTH_TOL:
        return LENGTH_LIMIT
    if t > horizon + 1e-9:
        return FIELD_END
    return RUNNING
