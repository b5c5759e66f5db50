"""The environment's compiled control step: winch rule, integration over one control interval,
observation, reward terms and episode-end checks in one call, for one environment or a batch.

The single environment and the vector environment call the same per-environment function
:func:`_step_one` (the vector env through :func:`step_parallel`, a ``prange`` over
environments), so environment i of a batch reproduces a single environment bit for bit.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from ..physics.core import FASTMATH, evaluate_tether
from ..physics.integrators import NONFINITE, rk4_advance, rk4_step, si_advance
from ..physics.layout import P_EA, P_MU, P_NEL, P_STRENGTH, P_W_LMAX, P_W_LMIN, P_W_VMAX
from ..physics.outputs import winch_end_tension
from ..physics.wind import W_UREF, air_velocity
from ..winch import brake_rule
from . import spaces as S

# --- configuration vector shared by all environments of a batch -----------------------------
C_DT = 0  # control step [s]
C_SEMI_IMPLICIT = 1  # 1: semi-implicit integrator, 0: RK4
C_SI_DT = 2  # largest semi-implicit step [s]
C_RK4_SAFETY = 3  # fraction of the RK4 stability bound
C_GROUND = 4  # ground-strike height of the CM [m] (one hull diameter)
C_BRAKE_SPEED = 5  # set-points below this engage the brake [m/s]
C_HOLD_SPEED = 6  # the brake clamps the drum below this reel speed [m/s]
C_SWL = 7  # safe working load [N]
C_FULL = 8  # 1: append the privileged full state to the observation
C_HORIZON = 9  # the turbulence field covers up to this time [s]
C_WEIGHTS = 10  # reward weights in spaces.REWARD_TERMS order
C_SIZE = C_WEIGHTS + len(S.REWARD_TERMS)
LENGTH_TOL = 1e-3  # [m] the winch's stopping profile keeps L inside its limits to << this

_JIT = {"cache": True, "error_model": "numpy", "fastmath": FASTMATH}


@njit(**_JIT)
def _wrap(a):
    """Angle wrapped to [-pi, pi)."""
    return a - 2.0 * math.pi * math.floor((a + math.pi) / (2.0 * math.pi))


@njit(**_JIT)
def observe(x, t, p, wp, wf, w, cfg, x_trim, T_trim, scale, lo, hi, obs):
    """Fill ``obs`` (float32) for state x at time t; returns the winch tension [N]."""
    n = int(p[P_NEL])
    o = 6 * (n - 1)
    evaluate_tether(t, x, p, wp, wf, w)
    T_w = winch_end_tension(x, p, w)
    ax, ay, az = air_velocity(x[o], x[o + 1], x[o + 2], t, wp, wf)
    raw = np.empty(S.N_OBS)
    for k in range(3):
        raw[k] = x[o + k] - x_trim[o + k]  # CM position minus trim
        raw[3 + k] = x[o + 3 + k]  # CM velocity
        raw[9 + k] = x[o + 9 + k]  # body rates
    raw[6] = x[o + 6] - x_trim[o + 6]
    raw[7] = x[o + 7] - x_trim[o + 7]
    raw[8] = _wrap(x[o + 8] - x_trim[o + 8])
    raw[12] = T_w
    raw[13] = T_w - T_trim
    raw[14] = x[o + 12] - x_trim[o + 12]
    raw[15] = x[o + 13]
    raw[16], raw[17], raw[18] = ax, ay, az
    for k in range(S.N_OBS):
        obs[k] = min(max(raw[k] / scale[k], lo[k]), hi[k])
    if cfg[C_FULL] != 0.0:
        lim = S.FULL_STATE_LIMIT
        obs[S.N_OBS] = min(wp[W_UREF], lim)
        for i in range(x.size):
            d = x[i] - x_trim[i]
            if i == o + 8:
                d = _wrap(d)
            obs[S.N_OBS + 1 + i] = min(max(d, -lim), lim)
    return T_w


@njit(**_JIT)
def _advance(x, t, u, p, wp, wf, w, cfg, stats):
    """Integrate one control interval with the configured integrator; returns its status."""
    n = int(p[P_NEL])
    dt = cfg[C_DT]
    if cfg[C_SEMI_IMPLICIT] != 0.0:
        h_max = cfg[C_SI_DT]
    else:  # the RK4 bound tightens as the tether is reeled in (shorter elements)
        h_max = rk4_step(p[P_EA], p[P_MU], x[6 * (n - 1) + 12] / n, cfg[C_RK4_SAFETY], n)
    nsteps = max(1, int(math.ceil(dt / h_max - 1e-9)))
    h = dt / nsteps
    if cfg[C_SEMI_IMPLICIT] != 0.0:
        return si_advance(x, t, h, nsteps, u, p, wp, wf, w, stats)
    return rk4_advance(x, t, h, nsteps, u, p, wp, wf, w, stats)


@njit(**_JIT)
def _outcome(x, t, p, peak, cfg):
    o = 6 * (int(p[P_NEL]) - 1)
    if peak > p[P_STRENGTH]:
        return S.TETHER_BREAK
    if x[o + 2] < cfg[C_GROUND]:
        return S.GROUND_STRIKE
    L = x[o + 12]
    if L < p[P_W_LMIN] - LENGTH_TOL or L > p[P_W_LMAX] + LENGTH_TOL:
        return S.LENGTH_LIMIT
    if t > cfg[C_HORIZON] + 1e-9:
        return S.FIELD_END
    return S.RUNNING


@njit(**_JIT)
def _rewards(obs, a, a_prev, peak, code, cfg, terms):
    wt = cfg[C_WEIGHTS:]
    # blow-by: horizontal motion only (the winch's own reeling moves the aerostat vertically)
    terms[0] = -wt[0] * (obs[0] ** 2 + obs[1] ** 2)
    terms[1] = -wt[1] * (obs[3] ** 2 + obs[4] ** 2)
    terms[2] = -wt[2] * obs[7] ** 2
    terms[3] = -wt[3] * obs[10] ** 2
    terms[4] = -wt[4] * a * a
    terms[5] = -wt[5] * (a - a_prev) ** 2
    terms[6] = -wt[6] * max(0.0, peak / cfg[C_SWL] - 1.0)
    ends = code != S.RUNNING and code != S.FIELD_END
    terms[7] = -wt[7] if ends else 0.0
    terms[8] = -wt[8] * obs[14] ** 2


@njit(**_JIT)
def _step_one(x, x_prev, t, a, a_prev, braked, p, wp, wf, w, cfg, x_trim, T_trim, scale, lo, hi,
              obs, terms):
    """One control step of one environment; returns (outcome code, brake state).

    a is the action in [-1, 1] (already clipped): set-point a * v_max through the winch's
    brake rule. On a non-finite state the state is restored to the start of the step, so the
    observation stays finite, and the outcome is NONFINITE.
    """
    n = int(p[P_NEL])
    iv = 6 * (n - 1) + 13
    v_set, brake, v_w = brake_rule(a * p[P_W_VMAX], False, braked, x[iv], p[P_W_VMAX],
                                   cfg[C_BRAKE_SPEED], cfg[C_HOLD_SPEED])
    x[iv] = v_w
    u = np.empty(2)
    u[0] = v_set
    u[1] = 1.0 if brake else 0.0
    x_prev[:] = x
    stats = np.empty(2)
    stats[0] = 0.0
    stats[1] = np.inf
    status = _advance(x, t, u, p, wp, wf, w, cfg, stats)
    t1 = t + cfg[C_DT]
    if status == NONFINITE:
        x[:] = x_prev
        observe(x, t, p, wp, wf, w, cfg, x_trim, T_trim, scale, lo, hi, obs)
        terms[:] = 0.0
        terms[7] = -cfg[C_WEIGHTS + 7]  # the termination term only
        return S.NONFINITE, brake
    observe(x, t1, p, wp, wf, w, cfg, x_trim, T_trim, scale, lo, hi, obs)
    code = _outcome(x, t1, p, stats[0], cfg)
    _rewards(obs, a, a_prev, stats[0], code, cfg, terms)
    return code, brake


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, parallel=True)
def step_parallel(active, X, Xp, T, A, AP, BR, P, WP, bank, KF, W, cfg, XT, TT, scale, lo, hi,
                  OBS, TERMS, CODE):
    """Step every environment i with active[i] (parallel over environments)."""
    for i in prange(X.shape[0]):
        if active[i]:
            code, br = _step_one(X[i], Xp[i], T[i], A[i], AP[i], BR[i], P[i], WP[i], bank[KF[i]],
                                 W[i], cfg, XT[i], TT[i], scale, lo, hi, OBS[i], TERMS[i])
            CODE[i] = code
            BR[i] = br
            T[i] += cfg[C_DT]
            AP[i] = A[i]


@njit(**_JIT)
def step_serial(X, Xp, T, A, AP, BR, P, WP, bank, KF, W, cfg, XT, TT, scale, lo, hi, OBS, TERMS,
                CODE):
    """The same step for one environment (index 0), without the thread pool."""
    code, br = _step_one(X[0], Xp[0], T[0], A[0], AP[0], BR[0], P[0], WP[0], bank[KF[0]], W[0],
                         cfg, XT[0], TT[0], scale, lo, hi, OBS[0], TERMS[0])
    CODE[0] = code
    BR[0] = br
    T[0] += cfg[C_DT]
    AP[0] = A[0]
