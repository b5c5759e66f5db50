"""Compiled integrators: each call advances the state over a whole interval of ``nsteps`` steps.

- :func:`rk4_advance`: classical fixed-step RK4, the reference. Its step comes from the axial
  stability bound of the tether (:func:`rk4_step`), capped at the aerostat's explicit step
  ``simulation.semi_implicit_dt``.
- :func:`si_advance`: a semi-implicit (linearly implicit, symplectic-Euler-like) step that
  treats the tether's element forces (axial stiffness, geometric stiffness T/l and internal
  damping) implicitly and everything else (aerodynamics, gravity, buoyancy, gyroscopic terms,
  winch) explicitly. First order; stable at steps of 50-150 ms. The implicit system is block
  tridiagonal along the tether (3x3 blocks per node, a 6x6 block for the aerostat) and is solved
  in O(n).

Both return a status code (``OK`` or ``NONFINITE``) and fill ``stats`` with the largest element
tension seen during the interval (stats[0]) and the smallest over the substeps of the largest
element tension (stats[1]; zero means the whole tether was slack at some instant);
:func:`advance_interval` adds the interval's end state to both.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .core import FASTMATH, _rotation, evaluate_tether, rhs
from .packing import P_DASHPOT, P_EA, P_FIXED, P_INERTIA, P_LEASH, P_ME, P_MU, P_NEL
from .state import (
    S_LENGTH,
    S_P,
    S_PHI,
    S_PSI,
    S_Q,
    S_R,
    S_REEL,
    S_THETA,
    S_VX,
    S_VY,
    S_VZ,
    aerostat_offset,
    node_vel_offset,
    tension_offset,
)

OK, NONFINITE = 0, 1
RK4_STABILITY = 2.0 * math.sqrt(2.0)  # RK4 stability limit on the imaginary axis, |lambda| h


@njit(cache=True)
def omega_max(EA: float, mu: float, l_u: float, n: int) -> float:
    """Highest axial frequency of the tether's interior chain (n - 1 nodes of mass mu l_u joined
    by springs EA / l_u between two much heavier or fixed ends):
    omega_max = 2 (c / l_u) sin((n - 1) pi / (2 n)), c = sqrt(EA / mu) the axial wave speed.
    For n = 1 there is no interior node; the bound 2 c / l_u is returned."""
    factor = math.sin((n - 1) * math.pi / (2 * n)) if n > 1 else 1.0
    return 2.0 * math.sqrt(EA / mu) / l_u * factor


@njit(cache=True)
def rk4_step(EA: float, mu: float, l_u: float, safety: float, n: int) -> float:
    """Largest stable RK4 step times the safety factor: safety * 2 sqrt(2) / omega_max.

    Measured: runs at 1.02 times this bound stay stable (the element damping moves the axial
    eigenvalues off the imaginary axis), so the default safety 0.9 leaves a real margin."""
    return safety * RK4_STABILITY / omega_max(EA, mu, l_u, n)


@njit(cache=True)
def rk4_interval_step(EA: float, mu: float, l_u: float, safety: float, n: int,
                      si_dt: float) -> float:
    """The RK4 step :func:`advance_interval` takes: the tether's axial bound (:func:`rk4_step`)
    capped at the aerostat's explicit step ``si_dt``. RK4 treats everything explicitly, and on a
    few long elements the axial bound is the looser one (two elements on 884 m under a 0.011x
    hull: axial bound 0.12 s, aerodynamic rate 35 /s at 25 m/s, |lambda| h = 4.2 > 2.8)."""
    return min(rk4_step(EA, mu, l_u, safety, n), si_dt)


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def _tension_stats(w, n, stats):
    T0 = tension_offset(n)
    tmax = 0.0
    for e in range(n):
        tmax = max(tmax, w[T0 + e])
    stats[0] = max(stats[0], tmax)
    stats[1] = min(stats[1], tmax)


@njit(cache=True, error_model="numpy", fastmath=FASTMATH)
def all_finite(x):
    """Every entry of x finite (FASTMATH keeps the NaN and infinity checks)."""
    for i in range(x.size):
        if not math.isfinite(x[i]):
            return False
    return True


@njit(cache=True, error_model="numpy", fastmath=FASTMATH)
def rk4_advance(x, t, h, nsteps, u, p, wp, wf, w, stats):
    """Advance x in place by nsteps RK4 steps of size h from time t."""
    m = x.size
    n = int(p[P_NEL])
    k1 = np.empty(m)
    k2 = np.empty(m)
    k3 = np.empty(m)
    k4 = np.empty(m)
    xt = np.empty(m)
    for s in range(nsteps):
        ts = t + s * h
        rhs(ts, x, u, p, wp, wf, k1, w)
        _tension_stats(w, n, stats)
        for i in range(m):
            xt[i] = x[i] + 0.5 * h * k1[i]
        rhs(ts + 0.5 * h, xt, u, p, wp, wf, k2, w)
        for i in range(m):
            xt[i] = x[i] + 0.5 * h * k2[i]
        rhs(ts + 0.5 * h, xt, u, p, wp, wf, k3, w)
        for i in range(m):
            xt[i] = x[i] + h * k3[i]
        rhs(ts + h, xt, u, p, wp, wf, k4, w)
        for i in range(m):
            x[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
    if not all_finite(x):
        return NONFINITE
    return OK


# --- small dense helpers for the semi-implicit solve ---------------------------------------------


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def _inv3(A, out):
    a, b, c = A[0, 0], A[0, 1], A[0, 2]
    d, e, f = A[1, 0], A[1, 1], A[1, 2]
    g, h, i = A[2, 0], A[2, 1], A[2, 2]
    co0, co1, co2 = e * i - f * h, f * g - d * i, d * h - e * g
    det = a * co0 + b * co1 + c * co2
    r = 1.0 / det
    out[0, 0], out[0, 1], out[0, 2] = co0 * r, (c * h - b * i) * r, (b * f - c * e) * r
    out[1, 0], out[1, 1], out[1, 2] = co1 * r, (a * i - c * g) * r, (c * d - a * f) * r
    out[2, 0], out[2, 1], out[2, 2] = co2 * r, (b * g - a * h) * r, (a * e - b * d) * r


@njit(cache=True, error_model="numpy", fastmath=FASTMATH)
def _solve_dense(A, b):
    """Solve A x = b in place (b overwritten) by Gaussian elimination with partial pivoting."""
    m = b.size
    for k in range(m):
        piv = k
        for i in range(k + 1, m):
            if abs(A[i, k]) > abs(A[piv, k]):
                piv = i
        if piv != k:
            for j in range(m):
                A[k, j], A[piv, j] = A[piv, j], A[k, j]
            b[k], b[piv] = b[piv], b[k]
        for i in range(k + 1, m):
            f = A[i, k] / A[k, k]
            for j in range(k, m):
                A[i, j] -= f * A[k, j]
            b[i] -= f * b[k]
    for k in range(m - 1, -1, -1):
        s = b[k]
        for j in range(k + 1, m):
            s -= A[k, j] * b[j]
        b[k] = s / A[k, k]


@njit(cache=True, error_model="numpy", fastmath=FASTMATH)
def _element_matrices(w, n, l_u, h, p, G, K):
    """Per element: K = (EA/l_u) e e^T + (T/l)(I - e e^T), C = c* e e^T; G = h^2 K + h C.

    Slack elements keep their axial stiffness in the matrix (not in the force), which keeps the
    step stable when an element goes in and out of tension.
    """
    T0 = tension_offset(n)
    EA, cs = p[P_EA], p[P_DASHPOT]
    for e in range(n):
        a, b = 3 * e, 3 * (e + 1)
        d0 = w[a] - w[b]
        d1 = w[a + 1] - w[b + 1]
        d2 = w[a + 2] - w[b + 2]
        ln = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        ev = (d0 / ln, d1 / ln, d2 / ln)
        T = w[T0 + e]
        kax = EA / l_u
        kg = T / ln
        c = cs if T > 0.0 else 0.0
        for i in range(3):
            for j in range(3):
                eij = ev[i] * ev[j]
                kij = kax * eij + kg * ((1.0 if i == j else 0.0) - eij)
                K[e, i, j] = kij
                G[e, i, j] = h * h * kij + h * c * eij


@njit(cache=True, error_model="numpy", fastmath=FASTMATH)
def si_advance(x, t, h, nsteps, u, p, wp, wf, w, stats):
    """Advance x in place by nsteps semi-implicit steps of size h from time t.

    With generalized velocities (tether node velocities; aerostat CM velocity and body rates)
    and the element forces linearized about the current state,
    (M + h C + h^2 K) dv = h M a(x_k, v_k) - h^2 K v_k,   v_{k+1} = v_k + dv,
    positions x_{k+1} = x_k + h v_{k+1}, Euler angles += h E(angles_k) omega_{k+1},
    where a is the full explicit acceleration from :func:`rhs`.
    """
    m = x.size
    n = int(p[P_NEL])
    nm = n - 1
    o = aerostat_offset(n)
    a = np.empty(m)
    G = np.empty((n, 3, 3))
    K = np.empty((n, 3, 3))
    Sinv = np.empty((max(nm, 1), 3, 3))
    Y = np.empty((max(nm, 1), 3))
    J = np.zeros((3, 6))  # confluence-point velocity = J [v_cm; omega]
    GJ = np.empty((3, 6))
    S0 = np.empty((6, 6))
    y0 = np.empty(6)
    tmp = np.empty((3, 3))
    for s in range(nsteps):
        ts = t + s * h
        rhs(ts, x, u, p, wp, wf, a, w)
        _tension_stats(w, n, stats)
        L = x[o + S_LENGTH]
        l_u = L / n
        mn = p[P_MU] * l_u
        _element_matrices(w, n, l_u, h, p, G, K)
        R = _rotation(x[o + S_PHI], x[o + S_THETA], x[o + S_PSI])
        # J = [I, -R S(r_l)]: d(confluence point) = d r_cm + R (dTheta x r_l)
        xl, yl, zl = p[P_LEASH], p[P_LEASH + 1], p[P_LEASH + 2]
        for i in range(3):
            J[i, i] = 1.0
            Ri0, Ri1, Ri2 = R[3 * i], R[3 * i + 1], R[3 * i + 2]
            # -(R S(r_l)) columns: S(r_l) = [[0,-zl,yl],[zl,0,-xl],[-yl,xl,0]]
            J[i, 3] = -(Ri1 * zl - Ri2 * yl)
            J[i, 4] = -(-Ri0 * zl + Ri2 * xl)
            J[i, 5] = -(Ri0 * yl - Ri1 * xl)
        # right-hand sides: h M a - h^2 K v (element relative velocities from the work array)
        V = node_vel_offset(n)
        for j in range(nm):
            for k in range(3):
                Y[j, k] = h * mn * a[3 * nm + 3 * j + k]
        _aerostat_rhs(x, a, p, R, h, o, y0)
        for e in range(n):
            dv0 = w[V + 3 * e] - w[V + 3 * e + 3]
            dv1 = w[V + 3 * e + 1] - w[V + 3 * e + 4]
            dv2 = w[V + 3 * e + 2] - w[V + 3 * e + 5]
            for k in range(3):
                f = h * h * (K[e, k, 0] * dv0 + K[e, k, 1] * dv1 + K[e, k, 2] * dv2)
                if e == 0:
                    for c in range(6):
                        y0[c] -= J[k, c] * f
                else:
                    Y[e - 1, k] -= f
                if e < nm:
                    Y[e, k] += f
        # forward elimination from the bottom node up
        for j in range(nm - 1, -1, -1):
            for r_ in range(3):
                for c in range(3):
                    tmp[r_, c] = G[j, r_, c] + G[j + 1, r_, c] + (mn if r_ == c else 0.0)
            if j < nm - 1:
                _eliminate(tmp, G[j + 1], Sinv[j + 1], Y[j], Y[j + 1])
            _inv3(tmp, Sinv[j])
        # aerostat block: M0 + J^T G0 J, minus the coupling to node 1
        _aerostat_matrix(x, p, R, o, S0)
        for r_ in range(3):
            for c in range(6):
                GJ[r_, c] = G[0, r_, 0] * J[0, c] + G[0, r_, 1] * J[1, c] + G[0, r_, 2] * J[2, c]
        for r_ in range(6):
            for c in range(6):
                S0[r_, c] += J[0, r_] * GJ[0, c] + J[1, r_] * GJ[1, c] + J[2, r_] * GJ[2, c]
        if nm > 0:
            _eliminate(S0, GJ, Sinv[0], y0, Y[0])
        _solve_dense(S0, y0)  # y0 now holds [dv_cm; domega]
        if p[P_FIXED] != 0.0:
            for c in range(6):
                y0[c] = 0.0
        # back substitution down the tether: dv_1 = S1^-1 (y1 + G0 J dq0), dv_{j+1} = ...
        for j in range(nm):
            if j == 0:
                g0 = g1 = g2 = 0.0
                for c in range(6):
                    g0 += GJ[0, c] * y0[c]
                    g1 += GJ[1, c] * y0[c]
                    g2 += GJ[2, c] * y0[c]
            else:
                d0, d1, d2 = Y[j - 1, 0], Y[j - 1, 1], Y[j - 1, 2]  # dv of node j (stored)
                g0 = G[j, 0, 0] * d0 + G[j, 0, 1] * d1 + G[j, 0, 2] * d2
                g1 = G[j, 1, 0] * d0 + G[j, 1, 1] * d1 + G[j, 1, 2] * d2
                g2 = G[j, 2, 0] * d0 + G[j, 2, 1] * d1 + G[j, 2, 2] * d2
            b0, b1, b2 = Y[j, 0] + g0, Y[j, 1] + g1, Y[j, 2] + g2
            for k in range(3):
                Y[j, k] = Sinv[j, k, 0] * b0 + Sinv[j, k, 1] * b1 + Sinv[j, k, 2] * b2
        # velocity and position updates (symplectic Euler)
        for j in range(nm):
            for k in range(3):
                x[3 * nm + 3 * j + k] += Y[j, k]
                x[3 * j + k] += h * x[3 * nm + 3 * j + k]
        for k in range(3):
            x[o + S_VX + k] += y0[k]
            x[o + k] += h * x[o + S_VX + k]
            x[o + S_P + k] += y0[3 + k]
        ph, th = x[o + S_PHI], x[o + S_THETA]
        pp, qq, rr = x[o + S_P], x[o + S_Q], x[o + S_R]
        cph, sph, cth = math.cos(ph), math.sin(ph), math.cos(th)
        x[o + S_PHI] += h * (pp + (qq * sph + rr * cph) * math.sin(th) / cth)
        x[o + S_THETA] += h * (qq * cph - rr * sph)
        x[o + S_PSI] += h * (qq * sph + rr * cph) / cth
        x[o + S_REEL] += h * a[o + S_REEL]
        x[o + S_LENGTH] += h * x[o + S_REEL]
    if not all_finite(x):
        return NONFINITE
    return OK


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def _eliminate(D, C, Sinv_below, y, y_below):
    """Eliminate the node below from a block row: D -= C^T S^-1 C, y += C^T S^-1 y_below.

    C couples the node below (3 rows) to this block's unknowns (columns: 3 for a tether node,
    where C is the symmetric element matrix G, or 6 for the aerostat, where C = G0 J).
    """
    m = D.shape[0]
    for r_ in range(m):
        for c in range(m):
            s = 0.0
            for k in range(3):
                for l2 in range(3):
                    s += C[k, r_] * Sinv_below[k, l2] * C[l2, c]
            D[r_, c] -= s
    for r_ in range(m):
        s = 0.0
        for k in range(3):
            t = 0.0
            for l2 in range(3):
                t += Sinv_below[k, l2] * y_below[l2]
            s += C[k, r_] * t
        y[r_] += s


@njit(cache=True, error_model="numpy", fastmath=FASTMATH)
def _aerostat_matrix(x, p, R, o, S0):
    """Generalized mass of the aerostat: blockdiag(R M_e R^T, I_body)."""
    for i in range(6):
        for j in range(6):
            S0[i, j] = 0.0
    for i in range(3):
        for j in range(3):
            s = 0.0
            for k in range(3):
                s += R[3 * i + k] * p[P_ME + k] * R[3 * j + k]
            S0[i, j] = s
            S0[3 + i, 3 + j] = p[P_INERTIA + 3 * i + j]


@njit(cache=True, error_model="numpy", fastmath=FASTMATH)
def _aerostat_rhs(x, a, p, R, h, o, y0):
    """h M a for the aerostat block: translation h R M_e R^T a_I, rotation h I domega."""
    for i in range(3):
        s = 0.0
        for k in range(3):
            ab = R[k] * a[o + S_VX] + R[3 + k] * a[o + S_VY] + R[6 + k] * a[o + S_VZ]  # body accel comp k
            s += R[3 * i + k] * p[P_ME + k] * ab
        y0[i] = h * s
        s = 0.0
        for k in range(3):
            s += p[P_INERTIA + 3 * i + k] * a[o + S_P + k]
        y0[3 + i] = h * s


# --- the interval advance shared by every front end -------------------------------------------------

#: Integration scheme vector, the compiled interval advance's settings (see :func:`scheme`).
SCHEME_SEMI_IMPLICIT = 0  # 1: semi-implicit step, 0: RK4
SCHEME_STEP = 1  # fixed step [s]; 0 picks the scheme's own (RK4 bound at the current L, or si_dt)
SCHEME_RK4_SAFETY = 2  # fraction of the RK4 axial stability bound
SCHEME_SI_DT = 3  # semi-implicit step [s]
SCHEME_SIZE = 4
INTEGRATORS = ("rk4", "semi-implicit")


def scheme(integrator: str, rk4_safety: float, si_dt: float, step: float | None = None) -> np.ndarray:
    """The scheme vector of :func:`advance_interval` for an integrator name ("rk4" or
    "semi-implicit"), its settings and an optional fixed step [s]."""
    out = np.zeros(SCHEME_SIZE)
    out[SCHEME_SEMI_IMPLICIT] = 1.0 if integrator == "semi-implicit" else 0.0
    out[SCHEME_STEP] = step or 0.0
    out[SCHEME_RK4_SAFETY] = rk4_safety
    out[SCHEME_SI_DT] = si_dt
    return out


@njit(cache=True, error_model="numpy", fastmath=FASTMATH)
def advance_interval(x, t, interval, u, p, wp, wf, w, sch, stats):
    """Advance x in place over ``interval`` seconds from time t with input u held; returns the
    status (``OK`` or ``NONFINITE``) and fills ``stats`` (module docstring).

    The interval is split into the fewest equal steps no longer than the scheme's step: a
    fixed step if one is set, else the semi-implicit step, or for RK4 the smaller of the
    tether's axial stability bound at the current paid-out length (it tightens as the tether is
    reeled in: shorter elements) and the semi-implicit step.
    The simulator (:meth:`aerostat_gym.sim.Model.advance`) and the environment's compiled
    control step both call this function, so they take the same steps bit for bit.
    """
    n = int(p[P_NEL])
    semi = sch[SCHEME_SEMI_IMPLICIT] != 0.0
    if sch[SCHEME_STEP] > 0.0:
        h_max = sch[SCHEME_STEP]
    elif semi:
        h_max = sch[SCHEME_SI_DT]
    else:
        L = x[aerostat_offset(n) + S_LENGTH]
        h_max = rk4_interval_step(p[P_EA], p[P_MU], L / n, sch[SCHEME_RK4_SAFETY], n,
                                  sch[SCHEME_SI_DT])
    nsteps = max(1, int(math.ceil(interval / h_max - 1e-9)))
    h = interval / nsteps
    if semi:
        status = si_advance(x, t, h, nsteps, u, p, wp, wf, w, stats)
    else:
        status = rk4_advance(x, t, h, nsteps, u, p, wp, wf, w, stats)
    if status == OK:
        # the interval's end state belongs to it: a tension its last step drives past the
        # strength is this interval's event, which a re-run of the interval can still resolve
        evaluate_tether(t + interval, x, p, wp, wf, w)
        _tension_stats(w, n, stats)
    return status
