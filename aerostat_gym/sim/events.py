"""Episode outcomes of a control step, decided in one compiled place.

The environments' compiled step (:mod:`aerostat_gym.envs.kernel`) and the simulator's
:func:`aerostat_gym.sim.simulate` both call :func:`step_outcome`, and both decide a terminating
step with :func:`aerostat_gym.sim.resolve.resolve`, so a tether break, a ground strike or a
length-limit excursion means the same thing in every front end.
"""

from __future__ import annotations

from numba import njit

from ..physics.core import FASTMATH
from ..physics.packing import P_ANCHOR, P_NEL, P_STRENGTH, P_W_LMAX, P_W_LMIN, P_W_VMAX
from ..physics.state import S_LENGTH, S_P, S_REEL, S_VX, S_X, S_Z, aerostat_offset

#: Outcome codes of a control step. DIVERGED and NONFINITE_OUTPUT are numerical failures, like
#: NONFINITE: the integration, not the physics, has gone wrong. DIVERGED is a finite state
#: beyond every physical bound (:func:`diverged`) or, in the environments, a terminating event
#: (break, ground strike, length limit) that finer integration steps show to come from an
#: integrator past its stability step, or that they cannot settle
#: (:func:`aerostat_gym.sim.resolve.resolve`). An event that only the coarse step sees (a
#: tension peak near the strength overshot) is not an outcome: the step is re-integrated.
(RUNNING, NONFINITE, TETHER_BREAK, GROUND_STRIKE, LENGTH_LIMIT, FIELD_END, DIVERGED,
 NONFINITE_OUTPUT) = range(8)
#: Reason strings (``info["termination"]``, ``info["failure"]``, ``info["truncation"]``).
OUTCOMES = {NONFINITE: "nonfinite_state", TETHER_BREAK: "tether_break",
            GROUND_STRIKE: "ground_strike", LENGTH_LIMIT: "length_limit",
            FIELD_END: "wind_field_exhausted", DIVERGED: "numerical_divergence",
            NONFINITE_OUTPUT: "nonfinite_output"}
#: The codes that are numerical failures (reported in ``info["failure"]`` too).
FAILURES = (NONFINITE, DIVERGED, NONFINITE_OUTPUT)
#: [m] the winch's stopping profile keeps L inside its limits to much better than this.
LENGTH_TOL = 1e-3
#: Bounds past which a finite state is a numerical divergence, not a physical event. Nothing in
#: a tethered aerostat moves at 1 km/s (three times the speed of sound, where the model's
#: incompressible aerodynamics means nothing), spins at 100 rad/s, strays ten line lengths from
#: its winch or loads its tether to 100 times the breaking strength: an explicit integrator past
#: its stability step reaches these within one control step (the RK4 amplification at 1.2 times
#: the bound is above 3 per substep), a physical break or ground strike never does.
SPEED_DIVERGED = 1.0e3  # [m/s] node or CM speed component
RATE_DIVERGED = 100.0  # [rad/s] body rate
REACH_DIVERGED = 10.0  # [-] distance from the anchor / longest line length
TENSION_DIVERGED = 100.0  # [-] peak element tension / tether strength
REEL_DIVERGED = 2.0  # [-] reel speed / rated drum speed (the overspeed brake holds it to 1)

_JIT = {"cache": True, "error_model": "numpy", "fastmath": FASTMATH}


@njit(**_JIT)
def tether_broken(peak_tension, strength):
    """An element tension above the tether's strength during the step breaks the tether."""
    return peak_tension > strength


@njit(**_JIT)
def diverged(x, p, peak_tension):
    """True when a finite state is beyond every physical bound (the ``*_DIVERGED`` constants):
    the integration has blown up."""
    n = int(p[P_NEL])
    o = aerostat_offset(n)
    if not peak_tension <= TENSION_DIVERGED * p[P_STRENGTH]:
        return True
    reach = REACH_DIVERGED * p[P_W_LMAX]
    for j in range(n - 1):  # moving tether nodes: positions then velocities
        for k in range(3):
            if not abs(x[3 * j + k] - p[P_ANCHOR + k]) <= reach:
                return True
            if not abs(x[3 * (n - 1) + 3 * j + k]) <= SPEED_DIVERGED:
                return True
    for k in range(3):
        if not abs(x[o + S_X + k] - p[P_ANCHOR + k]) <= reach or not abs(x[o + S_VX + k]) <= SPEED_DIVERGED:
            return True
        if not abs(x[o + S_P + k]) <= RATE_DIVERGED:
            return True
    return not abs(x[o + S_REEL]) <= REEL_DIVERGED * p[P_W_VMAX]


def ground_height(params) -> float:
    """CM height [m] below which the aerostat has struck the ground: one hull diameter (the
    model has no ground contact, so a run ends there)."""
    return float(params.aerostat.diameter)


@njit(**_JIT)
def terminating(code):
    """A physical event that ends a run (break, ground strike, length limit): re-run with finer
    steps before it stands (:func:`aerostat_gym.sim.resolve.resolve`)."""
    return code == TETHER_BREAK or code == GROUND_STRIKE or code == LENGTH_LIMIT


@njit(**_JIT)
def step_outcome(x, t, p, peak_tension, ground_height, horizon):
    """Outcome code at the end of a control step ending at time t.

    peak_tension : largest element tension over the step [N]. ground_height : CM height below
    which the aerostat has struck the ground [m]. horizon : last time the turbulence field
    covers [s] (inf for the environments' periodic fields). Checked in this order: numerical
    divergence (:func:`diverged`), break, ground strike, length outside the winch's limits,
    end of the wind field.
    """
    o = aerostat_offset(int(p[P_NEL]))
    if diverged(x, p, peak_tension):
        return DIVERGED
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
