"""Our tether with its top end driven along a path: the top end placed at every RK4 stage
(or semi-implicit step), and MoorDyn's segment rule and nodal drag as switches in our
right-hand side."""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ...physics.core import rhs
from ...physics.integrators import NONFINITE, OK, all_finite, si_advance
from ...physics.packing import P_CDN, P_DASHPOT, P_DIAM, P_EA, P_G, P_MU, P_NEL, P_RHO
from ...physics.state import (
    S_LENGTH,
    S_P,
    S_REEL,
    S_VX,
    S_X,
    aerostat_offset,
    node_force_offset,
    node_vel_offset,
    tension_offset,
)
from .cases import K_DIR, K_LEVER, K_TOP, path_displacement, path_length

# the aerostat block of the state, named once in aerostat_gym.physics.state
CM_POS, CM_VEL, RATES, LENGTH, LENGTH_RATE = S_X, S_VX, S_P, S_LENGTH, S_REEL


@njit(cache=True)
def _place_top(x, o, path, t, h_secant):
    """Put the top end and the unstretched length on the path at time t: CM position so that
    the confluence point is there, CM velocity (analytic, or the secant over [t, t + h_secant]
    when h_secant > 0), body rates zero, L and its rate."""
    s, sd = path_displacement(path, t)
    L, Ld = path_length(path, t)
    if h_secant > 0.0:
        s1 = path_displacement(path, t + h_secant)[0]
        sd = (s1 - s) / h_secant
        Ld = (path_length(path, t + h_secant)[0] - L) / h_secant
    for k in range(3):
        d = path[K_DIR + k]
        x[o + CM_POS + k] = path[K_TOP + k] + s * d + path[K_LEVER + k]
        x[o + CM_VEL + k] = sd * d
        x[o + RATES + k] = 0.0
    x[o + LENGTH] = L
    x[o + LENGTH_RATE] = Ld


@njit(cache=True)
def moordyn_segment_tension(x, p, w, e):
    """Axial force of element e under MoorDyn's rule (``Line::getStateDeriv``): the elastic
    part EA (l - l_u) / l_u only when stretched, plus the dashpot BA ldot / l_u (BA = b = c* l_u)
    always, so it acts on slack segments and may push; the strain rate has no unstretched-length
    term (ours: c* (ldot - l Ldot / L), the total clipped at zero). From the node positions and
    velocities of a work array filled by ``rhs``."""
    n = int(p[P_NEL])
    l_u = x[aerostat_offset(n) + LENGTH] / n
    V = node_vel_offset(n)
    pos, vel = w[:V], w[V:node_force_offset(n)]
    a = 3 * e
    d0, d1, d2 = pos[a] - pos[a + 3], pos[a + 1] - pos[a + 4], pos[a + 2] - pos[a + 5]
    ln = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
    ldot = (d0 * (vel[a] - vel[a + 3]) + d1 * (vel[a + 1] - vel[a + 4])
            + d2 * (vel[a + 2] - vel[a + 5])) / ln
    elastic = p[P_EA] * (ln / l_u - 1.0) if ln > l_u else 0.0
    return elastic + p[P_DASHPOT] * ldot, d0 / ln, d1 / ln, d2 / ln


@njit(cache=True)
def _apply_moordyn_rule(x, p, w, dx):
    """Replace our element tensions in the node accelerations dx by MoorDyn's rule
    (:func:`moordyn_segment_tension`): the switch that removes the damping-clip difference."""
    n = int(p[P_NEL])
    T0 = tension_offset(n)
    im_node = n / (p[P_MU] * x[aerostat_offset(n) + LENGTH])
    for e in range(n):
        T, ex, ey, ez = moordyn_segment_tension(x, p, w, e)
        dT = (T - w[T0 + e]) * im_node
        # node e (upper) is pulled toward the lower node by -T e; node e + 1 by +T e
        if e > 0:
            _add3(dx, 3 * (n - 1) + 3 * (e - 1), -dT * ex, -dT * ey, -dT * ez)
        if e < n - 1:
            _add3(dx, 3 * (n - 1) + 3 * e, dT * ex, dT * ey, dT * ez)


@njit(cache=True)
def _add3(a, i, vx, vy, vz):
    a[i] += vx
    a[i + 1] += vy
    a[i + 2] += vz


@njit(cache=True)
def node_unit(w, i, j):
    """Unit vector from node j to node i (positions in the work array) and the distance."""
    dx, dy, dz = w[3 * i] - w[3 * j], w[3 * i + 1] - w[3 * j + 1], w[3 * i + 2] - w[3 * j + 2]
    d = math.sqrt(dx * dx + dy * dy + dz * dz)
    return dx / d, dy / d, dz / d, d


@njit(cache=True)
def moordyn_node_drag(x, p, w, j, swap):
    """MoorDyn's drag on node j (``Line::getStateDeriv``): the relative flow
    u = U - v_j split along the node tangent q (internal nodes: from node j - 1 to j + 1; end
    nodes: their segment), D = 0.5 rho d l (Cd |u_p| u_p + pi CdAx |u_q| u_q) with l the node's
    share of the line (l_u inside, l_u / 2 at the ends), U = (swap[1], swap[2], swap[3]) the
    uniform current and CdAx = swap[4]."""
    n = int(p[P_NEL])
    l_u = x[aerostat_offset(n) + LENGTH] / n
    i0, i1 = max(j - 1, 0), min(j + 1, n)
    qx, qy, qz, _ = node_unit(w, i1, i0)
    length = l_u if 0 < j < n else 0.5 * l_u
    V = node_vel_offset(n)
    ux = swap[1] - w[V + 3 * j]
    uy = swap[2] - w[V + 3 * j + 1]
    uz = swap[3] - w[V + 3 * j + 2]
    uq = ux * qx + uy * qy + uz * qz
    px, py, pz = ux - uq * qx, uy - uq * qy, uz - uq * qz
    c = 0.5 * p[P_RHO] * p[P_DIAM] * length
    kp = c * p[P_CDN] * math.sqrt(px * px + py * py + pz * pz)
    kq = c * math.pi * swap[4] * abs(uq)
    return kp * px + kq * uq * qx, kp * py + kq * uq * qy, kp * pz + kq * uq * qz


@njit(cache=True)
def our_node_drag(x, p, w, j):
    """Our drag on node j (half of each adjacent element's), recovered from the node force in
    the work array: F_j - (tension terms) + weight."""
    n = int(p[P_NEL])
    F, T0 = node_force_offset(n), tension_offset(n)
    g = p[P_MU] * x[aerostat_offset(n) + LENGTH] / n * p[P_G] * (0.5 if j == 0 or j == n else 1.0)
    fx, fy, fz = w[F + 3 * j], w[F + 3 * j + 1], w[F + 3 * j + 2] + g
    if j > 0:  # element j - 1 above pulls node j up along its unit vector (upper minus lower)
        ex, ey, ez, _ = node_unit(w, j - 1, j)
        T = w[T0 + j - 1]
        fx, fy, fz = fx - T * ex, fy - T * ey, fz - T * ez
    if j < n:
        ex, ey, ez, _ = node_unit(w, j, j + 1)
        T = w[T0 + j]
        fx, fy, fz = fx + T * ex, fy + T * ey, fz + T * ez
    return fx, fy, fz


@njit(cache=True)
def _apply_moordyn_drag(x, p, w, dx, swap):
    """Replace our element-midpoint drag with loading functions in the node accelerations dx
    by MoorDyn's nodal crossflow drag (:func:`moordyn_node_drag`): the drag-law switch."""
    n = int(p[P_NEL])
    im_node = n / (p[P_MU] * x[aerostat_offset(n) + LENGTH])
    for j in range(1, n):
        mx, my, mz = moordyn_node_drag(x, p, w, j, swap)
        ox, oy, oz = our_node_drag(x, p, w, j)
        _add3(dx, 3 * (n - 1) + 3 * (j - 1), (mx - ox) * im_node, (my - oy) * im_node,
              (mz - oz) * im_node)


SWAP_SEGMENT_RULE, SWAP_NODAL_DRAG = 1, 2  # bits of swap[0]
NO_SWAP = np.zeros(5)


@njit(cache=True)
def _rhs_swapped(t, x, u, p, wp, wf, dx, w, swap):
    """Our right-hand side, with MoorDyn's segment rule and / or nodal drag in place of ours as
    the bits of swap[0] ask (``SWAP_SEGMENT_RULE``, ``SWAP_NODAL_DRAG``)."""
    rhs(t, x, u, p, wp, wf, dx, w)
    flags = int(swap[0])
    if flags & SWAP_NODAL_DRAG:
        _apply_moordyn_drag(x, p, w, dx, swap)
    if flags & SWAP_SEGMENT_RULE:
        _apply_moordyn_rule(x, p, w, dx)


@njit(cache=True)
def driven_rk4(x, t, h, nsteps, path, u, p, wp, wf, w, swap):
    """Advance the tether-only state x in place by ``nsteps`` RK4 steps of size h from time t,
    the top end (and unstretched length) on ``path`` at every stage time. The model must have
    the aerostat fixed (its derivatives zero) and u must brake the winch (L' = 0), so the RK4
    update leaves the overwritten entries alone. ``swap`` (``NO_SWAP``, or see
    :func:`_rhs_swapped`) puts MoorDyn's segment rule or nodal drag in place of ours. Returns OK
    or NONFINITE."""
    m = x.size
    o = aerostat_offset(int(p[P_NEL]))
    k1, k2, k3, k4, xt = np.empty(m), np.empty(m), np.empty(m), np.empty(m), np.empty(m)
    for s in range(nsteps):
        ts = t + s * h
        _place_top(x, o, path, ts, 0.0)
        _rhs_swapped(ts, x, u, p, wp, wf, k1, w, swap)
        for i in range(m):
            xt[i] = x[i] + 0.5 * h * k1[i]
        _place_top(xt, o, path, ts + 0.5 * h, 0.0)
        _rhs_swapped(ts + 0.5 * h, xt, u, p, wp, wf, k2, w, swap)
        for i in range(m):
            xt[i] = x[i] + 0.5 * h * k2[i]
        _place_top(xt, o, path, ts + 0.5 * h, 0.0)
        _rhs_swapped(ts + 0.5 * h, xt, u, p, wp, wf, k3, w, swap)
        for i in range(m):
            xt[i] = x[i] + h * k3[i]
        _place_top(xt, o, path, ts + h, 0.0)
        _rhs_swapped(ts + h, xt, u, p, wp, wf, k4, w, swap)
        for i in range(m):
            x[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
    _place_top(x, o, path, t + nsteps * h, 0.0)
    return OK if all_finite(x) else NONFINITE


@njit(cache=True)
def driven_si(x, t, h, nsteps, path, u, p, wp, wf, w, swap):
    """Advance x in place by ``nsteps`` semi-implicit steps of size h from time t, the top end
    placed on ``path`` at each step start with the secant velocity over the step (same model
    requirements as :func:`driven_rk4`). On return the top end carries its analytic velocity
    (for outputs). ``swap`` must be ``NO_SWAP`` (the semi-implicit step has no swapped
    variant). Returns OK or NONFINITE."""
    o = aerostat_offset(int(p[P_NEL]))
    stats = np.array([0.0, np.inf])
    for s in range(nsteps):
        ts = t + s * h
        _place_top(x, o, path, ts, h)
        if si_advance(x, ts, h, 1, u, p, wp, wf, w, stats) != OK:
            return NONFINITE
    _place_top(x, o, path, t + nsteps * h, 0.0)
    return OK
