"""The environment's compiled control step: winch rule, integration over one control interval,
observation, reward terms and episode-end checks in one call, for one environment or a batch.

The single environment and the vector environment call the same per-environment function
:func:`_step_one` (the vector env through :func:`step_parallel`, a ``prange`` over
environments), so environment i of a batch reproduces a single environment bit for bit. The
integration is the simulator's own interval advance
(:func:`aerostat_gym.physics.integrators.advance_interval`) and the episode-end check the
simulator's (:func:`aerostat_gym.sim.events.step_outcome`, a terminating step decided by
:func:`aerostat_gym.sim.resolve.resolve`, as :func:`aerostat_gym.sim.simulate` decides it):
nothing here is a second copy of the simulator.
"""

from __future__ import annotations

import math
import os

import numba
import numpy as np
from numba import njit, prange

from ..physics.core import FASTMATH, evaluate_tether
from ..physics.integrators import NONFINITE, SCHEME_SIZE, advance_interval
from ..physics.outputs import winch_tension
from ..physics.packing import P_NEL, P_W_VMAX
from ..physics.state import (
    S_LENGTH,
    S_P,
    S_PHI,
    S_PSI,
    S_REEL,
    S_THETA,
    S_VX,
    S_X,
    aerostat_offset,
)
from ..physics.wind import W_UREF, air_velocity
from ..sim import events as E
from ..sim.resolve import resolve
from ..sim.winch import brake_rule, brake_wanted
from . import reward as R
from . import spaces as S

# --- configuration vector shared by all environments of a batch -----------------------------
# It starts with the integration scheme vector of advance_interval (its SCHEME_* entries), so
# the configuration itself is passed as the scheme (to advance_interval and to
# sim.resolve.resolve, which shrinks the scheme's steps for its re-runs).
C_DT = SCHEME_SIZE  # control step [s]
C_GROUND = C_DT + 1  # ground-strike height of the CM [m] (one hull diameter)
C_BRAKE_SPEED = C_DT + 2  # stand-still band of the set-point [m/s]
C_HOLD_SPEED = C_DT + 3  # the brake clamps the drum below this reel speed [m/s]
C_SWL = C_DT + 4  # safe working load [N]
C_FULL = C_DT + 5  # 1: append the privileged full state to the observation
C_HORIZON = C_DT + 6  # the turbulence field covers up to this time [s]
C_FMAX = C_DT + 7  # the winch motor's force limit at the line [N] (over-haul detection)
C_BRAKE_DWELL = C_DT + 8  # the brake engages after this long inside the stand-still band [s]
C_LENGTH_BAND = C_DT + 9  # free band of the reward's length term (scaled length channel)
C_WEIGHTS = C_DT + 10  # reward weights in reward.REWARD_TERMS order
C_SIZE = C_WEIGHTS + len(R.REWARD_TERMS)

_JIT = {"cache": True, "error_model": "numpy", "fastmath": FASTMATH}

# Threading layer of the batched step. Numba's default pick is OpenMP, whose threads spin while
# they wait: on a shared machine a competing process then steals the spinning core and each
# parallel step waits for a time slice (measured on 2 cores with other jobs running, N = 64:
# OpenMP 7,400-14,000 env-steps/s with 2 threads against 67,000 with 1; OpenMP with passive
# waiting 56,000; the workqueue layer 57,000 with 2 threads and 61,000 with 1). The workqueue
# layer is therefore the default here; NUMBA_THREADING_LAYER set by the user takes precedence.
if "NUMBA_THREADING_LAYER" not in os.environ:
    numba.config.THREADING_LAYER = "workqueue"


@njit(**_JIT)
def _wrap(a):
    """Angle wrapped to [-pi, pi)."""
    return a - 2.0 * math.pi * math.floor((a + math.pi) / (2.0 * math.pi))


@njit(**_JIT)
def observe(x, t, p, wp, wf, w, cfg, x_trim, T_trim, scale, lo, hi, obs):
    """Fill ``obs`` (float32) for state x at time t; returns the winch tension [N], or NaN
    when any output is not finite (those channels are then written as 0, so ``obs`` is always
    finite; the caller classifies the step as a numerical failure).

    Channels in :data:`aerostat_gym.envs.spaces.CHANNELS` order: attitude deviations are
    theta - theta_trim etc. unchanged in sign (theta < 0 is nose up).
    """
    evaluate_tether(t, x, p, wp, wf, w)
    return _observe_evaluated(x, t, p, wp, wf, w, cfg, x_trim, T_trim, scale, lo, hi, obs)


@njit(**_JIT)
def _observe_evaluated(x, t, p, wp, wf, w, cfg, x_trim, T_trim, scale, lo, hi, obs):
    """:func:`observe` with the work array already holding state x at time t (as
    :func:`~aerostat_gym.physics.integrators.advance_interval` leaves its end state)."""
    n = int(p[P_NEL])
    o = aerostat_offset(n)
    T_w = winch_tension(x, p, w)
    ax, ay, az = air_velocity(x[o + S_X], x[o + S_X + 1], x[o + S_X + 2], t, wp, wf)
    raw = np.empty(S.N_OBS)
    for k in range(3):
        raw[S.OBS_DX + k] = x[o + S_X + k] - x_trim[o + S_X + k]  # CM position minus trim
        raw[S.OBS_VX + k] = x[o + S_VX + k]  # CM velocity
        raw[S.OBS_P + k] = x[o + S_P + k]  # body rates
    raw[S.OBS_DROLL] = x[o + S_PHI] - x_trim[o + S_PHI]
    raw[S.OBS_DPITCH] = x[o + S_THETA] - x_trim[o + S_THETA]
    raw[S.OBS_DYAW] = _wrap(x[o + S_PSI] - x_trim[o + S_PSI])
    raw[S.OBS_TENSION] = T_w
    raw[S.OBS_DTENSION] = T_w - T_trim
    raw[S.OBS_DLENGTH] = x[o + S_LENGTH] - x_trim[o + S_LENGTH]
    raw[S.OBS_REEL_SPEED] = x[o + S_REEL]
    raw[S.OBS_WIND_X], raw[S.OBS_WIND_Y], raw[S.OBS_WIND_Z] = ax, ay, az
    finite = True
    for k in range(S.N_OBS):
        v = raw[k] / scale[k]
        if not math.isfinite(v):
            finite = False
            v = 0.0
        obs[k] = min(max(v, lo[k]), hi[k])
    if cfg[C_FULL] != 0.0:
        lim = S.FULL_STATE_LIMIT
        obs[S.OBS_FULL_WIND] = min(wp[W_UREF], lim)
        for i in range(x.size):
            d = x[i] - x_trim[i]
            if i == o + S_PSI:
                d = _wrap(d)
            obs[S.OBS_FULL_STATE + i] = min(max(d, -lim), lim) if math.isfinite(d) else 0.0
    return T_w if finite else math.nan


@njit(**_JIT)
def _step_one(x, x_prev, t, a, a_prev, braked, quiet, p, wp, wf, w, cfg, x_trim, T_trim, scale,
              lo, hi, obs, terms):
    """One control step of one environment; returns (outcome code, brake state, stand-still
    time, peak tension).

    a is the action in [-1, 1] (already clipped): set-point a * v_max through the winch's
    brake logic (:func:`aerostat_gym.sim.winch.brake_wanted`, then ``brake_rule``, which reads
    the winch tension of the start state from the work array, filled by the observation of
    that state). On a non-finite state or non-finite outputs the state
    is restored to the start of the step, so the observation stays finite, and the outcome is
    NONFINITE or NONFINITE_OUTPUT; a finite state beyond physical bounds is DIVERGED.
    """
    iv = aerostat_offset(int(p[P_NEL])) + S_REEL
    v = a * p[P_W_VMAX]
    want, quiet = brake_wanted(v, False, quiet, cfg[C_DT], cfg[C_BRAKE_SPEED], cfg[C_BRAKE_DWELL])
    v_set, brake, v_w = brake_rule(v, want, braked, x[iv], p[P_W_VMAX], cfg[C_HOLD_SPEED],
                                   winch_tension(x, p, w), cfg[C_FMAX])
    x[iv] = v_w
    u = np.empty(2)
    u[0] = v_set
    u[1] = 1.0 if brake else 0.0
    x_prev[:] = x
    stats = np.empty(2)
    stats[0] = 0.0
    stats[1] = np.inf
    status = advance_interval(x, t, cfg[C_DT], u, p, wp, wf, w, cfg, stats)
    t1 = t + cfg[C_DT]
    if status == NONFINITE:
        return _failed(E.NONFINITE, x, x_prev, t, p, wp, wf, w, cfg, x_trim, T_trim, scale, lo,
                       hi, obs, terms), brake, quiet, 0.0
    # advance_interval has evaluated the tether at the end state into w
    if not math.isfinite(_observe_evaluated(x, t1, p, wp, wf, w, cfg, x_trim, T_trim, scale,
                                            lo, hi, obs)):
        return _failed(E.NONFINITE_OUTPUT, x, x_prev, t, p, wp, wf, w, cfg, x_trim, T_trim,
                       scale, lo, hi, obs, terms), brake, quiet, 0.0
    code = E.step_outcome(x, t1, p, stats[0], cfg[C_GROUND], cfg[C_HORIZON])
    if E.terminating(code):
        code = resolve(code, x, x_prev, t, cfg[C_DT], u, p, wp, wf, w, cfg, stats,
                       cfg[C_GROUND], cfg[C_HORIZON])
        # refill w, and observe the refined state when the step was re-integrated
        if not math.isfinite(observe(x, t1, p, wp, wf, w, cfg, x_trim, T_trim, scale, lo, hi,
                                     obs)):
            code = E.NONFINITE_OUTPUT
    if code == E.DIVERGED or code == E.NONFINITE_OUTPUT:
        return _failed(code, x, x_prev, t, p, wp, wf, w, cfg, x_trim, T_trim, scale, lo, hi,
                       obs, terms), brake, quiet, 0.0
    R.reward_terms(obs, a, a_prev, stats[0], code, cfg[C_WEIGHTS:], cfg[C_SWL],
                   cfg[C_LENGTH_BAND], terms)
    return code, brake, quiet, stats[0]


@njit(**_JIT)
def _failed(code, x, x_prev, t, p, wp, wf, w, cfg, x_trim, T_trim, scale, lo, hi, obs, terms):
    """A numerical failure: restore the start-of-step state and its (finite) observation,
    keep only the termination reward term; returns the outcome code."""
    x[:] = x_prev
    observe(x, t, p, wp, wf, w, cfg, x_trim, T_trim, scale, lo, hi, obs)
    terms[:] = 0.0
    terms[R.R_TERMINATION] = -cfg[C_WEIGHTS + R.R_TERMINATION]
    return code


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, parallel=True)
def step_parallel(active, state, state_prev, time, action, action_prev, braked, quiet, packed,
                  wind, bank, field_index, work, cfg, trim_state, trim_tension, scale, lo, hi,
                  obs, terms, code, peak):
    """Step every environment i with active[i] (parallel over environments)."""
    for i in prange(state.shape[0]):
        if active[i]:
            _step_slot(i, state, state_prev, time, action, action_prev, braked, quiet, packed,
                       wind, bank, field_index, work, cfg, trim_state, trim_tension, scale, lo,
                       hi, obs, terms, code, peak)


@njit(**_JIT)
def step_serial(state, state_prev, time, action, action_prev, braked, quiet, packed, wind,
                bank, field_index, work, cfg, trim_state, trim_tension, scale, lo, hi, obs, terms,
                code, peak):
    """The same step for one environment (index 0), without the thread pool."""
    _step_slot(0, state, state_prev, time, action, action_prev, braked, quiet, packed, wind,
               bank, field_index, work, cfg, trim_state, trim_tension, scale, lo, hi, obs, terms,
               code, peak)


@njit(**{**_JIT, "inline": "always"})
def _step_slot(i, state, state_prev, time, action, action_prev, braked, quiet, packed, wind,
               bank, field_index, work, cfg, trim_state, trim_tension, scale, lo, hi, obs, terms,
               code, peak):
    """Step slot i of the batch arrays and advance its clock, winch logic and action memory."""
    c, br, qt, pk = _step_one(state[i], state_prev[i], time[i], action[i], action_prev[i],
                              braked[i], quiet[i], packed[i], wind[i], bank[field_index[i]],
                              work[i], cfg, trim_state[i], trim_tension[i], scale, lo, hi, obs[i],
                              terms[i])
    code[i] = c
    braked[i] = br
    quiet[i] = qt
    peak[i] = pk
    time[i] += cfg[C_DT]
    action_prev[i] = action[i]
