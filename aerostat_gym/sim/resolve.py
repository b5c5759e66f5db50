"""The decision of a terminating control step, shared by every front end.

A control step that ends in a tether break, a ground strike or a length-limit excursion
(:func:`aerostat_gym.sim.events.step_outcome`) is re-run from its start with finer integration
steps before it ends a run: an integrator past its stability step is a numerical divergence,
not a physical event, and an event that only the coarse step sees (a tension peak near the
strength overshot) is no event. The environments' compiled step
(:mod:`aerostat_gym.envs.kernel`) and the simulator's :func:`aerostat_gym.sim.simulate` both
call :func:`resolve`, so an outcome means the same in each.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ..physics.core import FASTMATH
from ..physics.integrators import NONFINITE as INTEGRATION_FAILED
from ..physics.integrators import (
    SCHEME_RK4_SAFETY,
    SCHEME_SEMI_IMPLICIT,
    SCHEME_SI_DT,
    SCHEME_STEP,
    advance_interval,
)
from ..physics.packing import P_STRENGTH
from .events import DIVERGED, NONFINITE, TETHER_BREAK, step_outcome

_JIT = {"cache": True, "error_model": "numpy", "fastmath": FASTMATH}


#: [-] a terminating step is physical when half the integration step reproduces its end state
#: to this fraction of the state's largest entry (integration error is far smaller; an
#: integrator past its stability step misses by orders of magnitude)
REPRODUCE_TOL = 1e-3
#: Finest re-run of a terminating step that half the step does not reproduce: the integration
#: step over 2**MAX_REFINE (3 ms for the semi-implicit 50 ms)
MAX_REFINE = 4


@njit(**_JIT)
def _rerun(level, x_out, x_prev, t, dt, u, p, wp, wf, w, scheme, stats, ground, horizon):
    """The control step from x_prev again, at the integration step over 2**level, into x_out
    and stats; returns its outcome code (NONFINITE when the integration fails)."""
    fine = scheme.copy()
    shrink = 0.5 ** level
    fine[SCHEME_RK4_SAFETY] *= shrink
    fine[SCHEME_SI_DT] *= shrink
    fine[SCHEME_STEP] *= shrink
    x_out[:] = x_prev
    stats[0] = 0.0
    stats[1] = np.inf
    if advance_interval(x_out, t, dt, u, p, wp, wf, w, fine, stats) == INTEGRATION_FAILED:
        return NONFINITE
    return step_outcome(x_out, t + dt, p, stats[0], ground, horizon)


@njit(**_JIT)
def _same_end(a, b):
    """End states within REPRODUCE_TOL of the larger state's largest entry (at least 1)."""
    big = 1.0
    for i in range(a.size):
        big = max(big, abs(a[i]), abs(b[i]))
    for i in range(a.size):
        if not abs(a[i] - b[i]) <= REPRODUCE_TOL * big:
            return False
    return True


@njit(**_JIT)
def _gap(a, b):
    """Largest entry of |a - b|."""
    g = 0.0
    for i in range(a.size):
        g = max(g, abs(a[i] - b[i]))
    return g


#: Largest ratio |x(h) - x(h/2)| / |x(h/2) - x(h/4)| of a step that is merely inaccurate at h:
#: a converging first-order step halves its error with the step (ratio 2; the semi-implicit
#: scheme, and RK4 too once slack elements or the brake make the response non-smooth), here
#: with a margin of 2. A step past its stability bound, or one from a state an unstable step
#: has already corrupted, misses by more (RK4 at 1.4 times its bound: 5.5-6.5).
ERROR_RATIO_LIMIT = 4.0


#: [-] a break whose peak tension half the step misses by more than this factor is an unstable
#: step (RK4 past its bound): DIVERGED
BREAK_PEAK_RATIO = 2.0
#: [-] the semi-implicit step's tether-break peaks count as settled when two successive step
#: sizes give them within this ratio (a physical break: 36.2 and 36.3 kN at 50 and 25 ms)
SNAP_PEAK_RATIO = 1.1


@njit(**_JIT)
def _within(a, b, ratio):
    """a and b within a factor ``ratio`` of each other."""
    return b / ratio <= a <= b * ratio


@njit(**_JIT)
def resolve(code, x, x_prev, t, dt, u, p, wp, wf, w, scheme, stats, ground, horizon):
    """Decide a terminating control step (tether break, ground strike, length limit) by
    re-running it from x_prev with finer integration steps. Returns the outcome code; x and
    stats hold the state and tension statistics the run goes on from. Runs only on a
    terminating step.

    The step ran from x_prev at time t over ``dt`` with the winch input u held; ``scheme`` is
    the interval advance's scheme vector (a longer vector that starts with it serves: the
    environments pass their configuration); ``ground`` and ``horizon`` are those of
    :func:`aerostat_gym.sim.events.step_outcome`.

    - A semi-implicit break whose peak tension half the step does not reproduce within
      SNAP_PEAK_RATIO is decided by :func:`_settle_snap`.
    - Half the step reproduces the event (the same event, for a break with a peak tension
      within BREAK_PEAK_RATIO, or an end state within REPRODUCE_TOL): the event is physical and
      the step stands.
    - Half the step fails, or (for a break) its peak tension differs by more than
      BREAK_PEAK_RATIO: the integrator was past its stability step (it is stable at half the
      step, or blows up differently): DIVERGED.
    - The coarse step's difference from half the step is more than ERROR_RATIO_LIMIT times
      half the step's difference from a quarter: not an inaccurate step but an unstable one
      (or one from a state an unstable step has corrupted): DIVERGED.
    - Otherwise the coarse step misjudged the response (typically a tension peak near the
      strength overshot by a few per cent in a violent excursion): the step is halved again
      until two successive halvings agree on the outcome, and the finer of the two stands,
      event or not (no event: the episode goes on from the refined state). No agreement by
      MAX_REFINE halvings: DIVERGED.
    """
    peak, least = stats[0], stats[1]
    coarse = np.empty(x.size)
    fine = np.empty(x.size)
    got = _rerun(1, coarse, x_prev, t, dt, u, p, wp, wf, w, scheme, stats, ground, horizon)
    if got == NONFINITE or got == DIVERGED:
        return DIVERGED
    if code == TETHER_BREAK and scheme[SCHEME_SEMI_IMPLICIT] != 0.0 \
            and not _within(stats[0], peak, SNAP_PEAK_RATIO):
        return _settle_snap(got, x, x_prev, t, dt, u, p, wp, wf, w, scheme, stats, ground,
                           horizon, fine)
    if code == TETHER_BREAK and not _within(stats[0], peak, BREAK_PEAK_RATIO):
        return DIVERGED
    if got == code or _same_end(coarse, x):
        stats[0], stats[1] = peak, least  # the original step stands (x untouched)
        return code
    coarse_error = _gap(x, coarse)
    for level in range(2, MAX_REFINE + 1):
        finer = _rerun(level, fine, x_prev, t, dt, u, p, wp, wf, w, scheme, stats, ground,
                       horizon)
        if finer == NONFINITE or finer == DIVERGED:
            return DIVERGED
        if level == 2 and not coarse_error <= ERROR_RATIO_LIMIT * _gap(coarse, fine):
            return DIVERGED
        if finer == got:
            x[:] = fine
            return finer
        got = finer
    return DIVERGED


@njit(**_JIT)
def _settle_snap(got, x, x_prev, t, dt, u, p, wp, wf, w, scheme, stats, ground, horizon, fine):
    """A semi-implicit tether break that half the step (outcome ``got``, peak in stats[0])
    does not reproduce. The scheme keeps the tether's stiffness implicit, so this is not an
    instability but the snap of a slack element that goes taut within one step: it is
    stretched by its closing speed times the step, on short stiff elements a spike far above
    the physical snap load (measured, 55 m on 24 elements at 20 m/s in severe turbulence: 750,
    262, 55 and 33.2 kN at 50, 25, 12.5 and 6.25 ms, 33.2 kN below at 3.1 ms; the strength is
    35.6 kN). The step is halved until two successive halvings agree on the outcome and on the
    peak tension, within SNAP_PEAK_RATIO or both that far below the strength (a slack,
    snapping tether's small peaks do not converge in ratio: 0.2, 0.3, 0.4 kN); the finer
    stands, break or not. No agreement by MAX_REFINE halvings, or a failed re-run: DIVERGED."""
    last_peak = stats[0]
    for level in range(2, MAX_REFINE + 1):
        finer = _rerun(level, fine, x_prev, t, dt, u, p, wp, wf, w, scheme, stats, ground,
                       horizon)
        if finer == NONFINITE or finer == DIVERGED:
            return DIVERGED
        settled = _within(stats[0], last_peak, SNAP_PEAK_RATIO) \
            or max(stats[0], last_peak) < p[P_STRENGTH] / SNAP_PEAK_RATIO
        if finer == got and settled:
            x[:] = fine
            return finer
        got, last_peak = finer, stats[0]
    return DIVERGED
