"""The right-hand side of the tethered-aerostat model, compiled with numba.

One function, :func:`rhs`, is the single source of truth: the integrators, the trim solver, the
linearization (and therefore the LQR baseline) and the environment all call it.

Frames and signs (written once, here)
-------------------------------------
- Inertial frame: origin at the winch/anchor, Z up; the default mean wind blows toward +X.
- Body frame: origin at the CM, x toward the nose, y to port, z up ([LN02]). Attitude by Z-Y-X
  Euler angles (psi, theta, phi): R = Rz(psi) Ry(theta) Rx(phi) maps body to inertial
  components. theta < 0 is nose up. At trim in a +X wind the nose points upwind, psi = pi.
- Body rates (p, q, r) about body x, y, z.

Model ([LN02]; equations reconstructed in docs/parameters.md section 4)
-----------------------------------------------------------------------
- Tether: n elements between node 1 (the confluence point, rigidly attached to the aerostat)
  and node n + 1 (the anchor). Element mass mu l_u lumped half to each end node; the top half
  mass weighs on the aerostat at the confluence point. Tension-only viscoelastic elements
  T = EA eps + b deps/dt with l_u = L / n and b = c* l_u, so T = EA eps + c* (ldot - l Ldot / L).
  Morison drag with loading functions from each element's midpoint velocity relative to the
  air, half to each end node; gravity on every node.
- Aerostat: buoyancy B = rho g V at the centre of buoyancy, weight at the CM, Jones & DeLaurier
  hull forces and nose moment (applied as forces at the nose plus the moment, which equals
  forces at the centre of pressure and has no 0/0 at alpha -> 0), three fins with local alpha
  from the air-relative velocity at their own point (V + omega x r - wind), linear lift and
  induced drag to a 3-D stall angle, then the Viterna-Corrigan post-stall normal force out to
  90 deg and its mirror image in reverse flow (:func:`fin_coefficients`; the paper's flat
  post-stall lift is the option ``fins.post_stall = 'flat'``).
- Air inertia: in accelerating air (turbulence, gusts) the hull feels the Froude-Krylov force
  rho V dW/dt plus the added-mass force k_i rho V dW_i/dt per body axis, applied at the
  centre of buoyancy (:func:`air_inertia_load`); dW/dt is the local time derivative at the hull
  point averaged over the hull length along the wind
  (:func:`aerostat_gym.physics.wind.air_acceleration`). Zero in steady wind.
- Inertia: translational added mass m_e = m + k rho V per body axis. The inertial terms use
  Kirchhoff's form M_e dV/dt + omega x (M_e V) = F and I domega/dt + omega x I omega
  + V x (M_a V) = M with V the ground-relative CM velocity. This is the rigid-body mechanics of
  an anisotropic inertia, conserves energy exactly, and equals [LN02]'s m_e (dV/dt + omega x V)
  to first order about any trim (where V = 0), so trim and linearization are [LN02]'s. The
  steady-flow Munk moment stays in the hull's (k3 - k1) eta_k terms on the air-relative velocity.
- Winch: reel-out speed set-point through a speed loop (first-order lag with acceleration and
  speed limits) acting on a drivetrain reflected to the line (equivalent mass, Coulomb and
  viscous friction, motor force limit); the brake holds the drum.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .packing import (
    P_AF,
    P_AILEN,
    P_AIRINERTIA,
    P_ANCHOR,
    P_ASTALL,
    P_BUOY,
    P_CB,
    P_CD0F,
    P_CD0H,
    P_CDC,
    P_CDMAX,
    P_CDN,
    P_CLA,
    P_DASHPOT,
    P_DIAM,
    P_EA,
    P_FIN,
    P_FIXED,
    P_FN,
    P_FT,
    P_G,
    P_I1,
    P_I3,
    P_IINV,
    P_INERTIA,
    P_J1,
    P_J2,
    P_KIND,
    P_KPOT,
    P_LEASH,
    P_MA,
    P_MASS,
    P_ME,
    P_MU,
    P_NEL,
    P_NFIN,
    P_NOSE,
    P_POSTSTALL,
    P_RHO,
    P_SH,
    P_W_AMAX,
    P_W_CV,
    P_W_FC,
    P_W_FMAX,
    P_W_FRICTION_V,
    P_W_LMAX,
    P_W_LMIN,
    P_W_MEQ,
    P_W_TAU,
    P_W_VMAX,
)
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
    node_force_offset,
    node_vel_offset,
    points_offset,
    scratch_offset,
    tension_offset,
)
from .wind import (
    W_DIRC,
    W_DIRS,
    W_GUST_ON,
    W_PROFILE,
    W_TURB_ON,
    W_UREF,
    air_acceleration,
    air_velocity,
    mean_speed,
)

# fastmath without the no-NaN/no-Inf assumptions, so non-finite states are still detected.
# With contraction (FMA) and reassociation the semi-implicit step's rounding depends on how the
# kernels were compiled: the process that compiles them and later ones that load the cache
# differ by about 1e-12 (README, Guarantees: Determinism); without both it is bit for bit
# and the step about 10 % slower.
FASTMATH = {"nsz", "arcp", "contract", "afn", "reassoc"}

# Work-array layout: see aerostat_gym.physics.state.
#
# The loops index the work array through views (w[a:b]) with indices from range(): numba wraps
# negative indices, and with an offset computed at run time (w[base + i]) every access carries
# that select, which also keeps LLVM from vectorizing. Measured: 0.42 -> 0.29 us per call.


# atan(r) = r P(r^2) on [0, 1], least-squares fit on Chebyshev nodes: max error 8.3e-12 rad.
# Used instead of math.atan2 in the loading functions and fin angles (13 atan2 per RHS call).
_ATAN_C = (0.999999999996503, -0.3333333310350973, 0.19999984562222467, -0.1428533158589695,
           0.1110626414598247, -0.09054362224365327, 0.07513230362760116, -0.06063488520294236,
           0.044282885594268885, -0.026656175176109326, 0.011850251192783857,
           -0.0033536231441468126, 0.000445188573384353)


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def _atan01(r):
    """r P(r^2) evaluated by Estrin's scheme: the Horner sum regrouped into independent pairs,
    so the dependency chain is ~5 multiply-adds deep instead of 13."""
    z = r * r
    z2 = z * z
    z4 = z2 * z2
    c = _ATAN_C
    lo = (c[0] + z * c[1]) + z2 * (c[2] + z * c[3]) + z4 * ((c[4] + z * c[5]) + z2 * (c[6] + z * c[7]))
    hi = (c[8] + z * c[9]) + z2 * (c[10] + z * c[11]) + z4 * c[12]
    return r * (lo + (z4 * z4) * hi)


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def fast_atan2(y, x):
    """atan2(y, x) to 1e-11 rad via octant reduction and :data:`_ATAN_C`. Written with selects
    rather than branches (the signs flip with the state, so branches would mispredict);
    atan2(0, 0) = 0."""
    ax, ay = abs(x), abs(y)
    swap = ay > ax
    a = _atan01(min(ax, ay) / max(ax, ay, 1e-300))
    a = 0.5 * math.pi - a if swap else a
    a = math.pi - a if x < 0.0 else a
    return -a if y < 0.0 else a


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def _rotation(ph, th, ps):
    cph, sph = math.cos(ph), math.sin(ph)
    cth, sth = math.cos(th), math.sin(th)
    cps, sps = math.cos(ps), math.sin(ps)
    return (cth * cps, sph * sth * cps - cph * sps, cph * sth * cps + sph * sps,
            cth * sps, sph * sth * sps + cph * cps, cph * sth * sps - sph * cps,
            -sth, sph * cth, cph * cth, cph, sph, cth, sth)


@njit(cache=True, error_model="numpy", fastmath=FASTMATH)
def rotation_matrix(ph, th, ps):
    """Body-to-inertial rotation matrix for Z-Y-X Euler angles (3x3 array)."""
    r = _rotation(ph, th, ps)[:9]
    out = np.empty((3, 3))
    for i in range(9):
        out[i // 3, i % 3] = r[i]
    return out


def euler_angles(R: np.ndarray) -> tuple[float, float, float]:
    """Z-Y-X Euler angles (phi, theta, psi) of a body-to-inertial rotation matrix, the inverse
    of :func:`rotation_matrix` for |theta| < pi/2."""
    return (math.atan2(R[2, 1], R[2, 2]), -math.asin(max(-1.0, min(1.0, R[2, 0]))),
            math.atan2(R[1, 0], R[0, 0]))


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def _kinematics(x, p, R, w):
    """Fill the work array with node positions and velocities (node 0 = confluence point from
    the aerostat state, node n = anchor) and the points where the wind is sampled: element
    midpoints, then the hull point (centre of buoyancy), then each fin's point."""
    n = int(p[P_NEL])
    nm = n - 1
    o = aerostat_offset(n)
    V, PT = node_vel_offset(n), points_offset(n)
    xl, yl, zl = p[P_LEASH], p[P_LEASH + 1], p[P_LEASH + 2]
    pp, qq, rr = x[o + S_P], x[o + S_Q], x[o + S_R]
    wx, wy, wz = qq * zl - rr * yl, rr * xl - pp * zl, pp * yl - qq * xl
    for k in range(3):
        # confluence point r_cm + R r_l, velocity v_cm + R (omega x r_l)
        w[k] = x[o + k] + R[3 * k] * xl + R[3 * k + 1] * yl + R[3 * k + 2] * zl
        w[V + k] = x[o + S_VX + k] + R[3 * k] * wx + R[3 * k + 1] * wy + R[3 * k + 2] * wz
        w[3 * n + k] = p[P_ANCHOR + k]
        w[V + 3 * n + k] = 0.0
    # views: indices from range() are known non-negative (no wraparound selects)
    pos, vel, mid = w[:V], w[V:node_force_offset(n)], w[PT:PT + 3 * n]
    xp, xv = x[:3 * nm], x[3 * nm:6 * nm]
    for i in range(3 * nm):
        pos[3 + i] = xp[i]
        vel[3 + i] = xv[i]
    for i in range(3 * n):
        mid[i] = 0.5 * (pos[i] + pos[3 + i])
    nf = int(p[P_NFIN])
    for c in range(nf + 1):
        b = P_CB if c == 0 else P_FIN + 9 * (c - 1)
        cx, cy, cz = p[b], p[b + 1], p[b + 2]
        for k in range(3):
            w[PT + 3 * (n + c) + k] = x[o + k] + R[3 * k] * cx + R[3 * k + 1] * cy + R[3 * k + 2] * cz
    return n + nf + 1


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def wind_batch(t, w, npts, base, wp, wf):
    """Air velocity at the npts points stored from ``w[base]``, written just after them.

    Branches once on the wind features: a steady mean wind (the trim and the paper's case)
    takes a short path; gusts and turbulence go through :func:`air_velocity` point by point.
    """
    pts, out = w[base:base + 3 * npts], w[base + 3 * npts:base + 6 * npts]
    if wp[W_GUST_ON] == 0.0 and (wp[W_TURB_ON] == 0.0 or wf.shape[1] < 2):
        c, s = wp[W_DIRC], wp[W_DIRS]
        uniform = wp[W_PROFILE] == 0.0
        u0 = wp[W_UREF]
        for i in range(npts):
            um = u0 if uniform else mean_speed(pts[3 * i + 2], wp)
            out[3 * i] = c * um
            out[3 * i + 1] = s * um
            out[3 * i + 2] = 0.0
        return
    for i in range(npts):
        ax, ay, az = air_velocity(pts[3 * i], pts[3 * i + 1], pts[3 * i + 2], t, wp, wf)
        out[3 * i] = ax
        out[3 * i + 1] = ay
        out[3 * i + 2] = az


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def _tether(x, p, w):
    """Element tensions and node forces of the tether (inertial), from the kinematics and the
    winds already in the work array. Node 0's force acts on the aerostat. Returns the
    winch-end element tension.

    Three passes over the elements: geometry and tension (:func:`_element_geometry`), the drag
    magnitudes (:func:`_element_drag`, branch-free on contiguous pairs, so LLVM vectorizes its
    square roots, divisions and arctangent), then the per-element forces gathered at the nodes
    (:func:`_node_forces`). Short loop bodies also let the out-of-order core overlap the
    square-root/division chains of consecutive elements.
    """
    n = int(p[P_NEL])
    _element_geometry(x, p, w, n)
    _element_drag(x, p, w, n)
    _node_forces(x, p, w, n)
    return w[tension_offset(n) + n - 1]


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def _element_geometry(x, p, w, n):
    """Per element: unit vector e (upper minus lower node), tension, and the midpoint velocity
    relative to the air split into its tangential part v_t = v.e and normal part v_n."""
    o = aerostat_offset(n)
    L = x[o + S_LENGTH]
    l_u = L / n
    il_u = 1.0 / l_u
    rate = x[o + S_REEL] / L  # Ldot / L: the strain rate's unstretched-length term
    EA, cs = p[P_EA], p[P_DASHPOT]
    # views of the work array (indices from range() are then known non-negative: no
    # wraparound selects in the loop)
    V, T0 = node_vel_offset(n), tension_offset(n)
    pos, vel, ten = w[:V], w[V:node_force_offset(n)], w[T0:T0 + n]
    wn, vv, ev = _element_views(p, w, n)
    for e in range(n):
        a = 3 * e
        dx = pos[a] - pos[a + 3]
        dy = pos[a + 1] - pos[a + 4]
        dz = pos[a + 2] - pos[a + 5]
        ln = math.sqrt(dx * dx + dy * dy + dz * dz)
        il = 1.0 / ln
        ex, ey, ez = dx * il, dy * il, dz * il
        # tension only: a slack element carries nothing, and damping cannot push
        T = EA * (ln * il_u - 1.0) + cs * (ex * (vel[a] - vel[a + 3]) + ey * (vel[a + 1] - vel[a + 4])
                                         + ez * (vel[a + 2] - vel[a + 5]) - ln * rate)
        ten[e] = max(T, 0.0) if ln > l_u else 0.0
        # midpoint velocity relative to the air; its normal component, one definition
        vx = 0.5 * (vel[a] + vel[a + 3]) - wn[a]
        vy = 0.5 * (vel[a + 1] + vel[a + 4]) - wn[a + 1]
        vz = 0.5 * (vel[a + 2] + vel[a + 5]) - wn[a + 2]
        vt = vx * ex + vy * ey + vz * ez
        nx, ny, nz = vx - vt * ex, vy - vt * ey, vz - vt * ez
        vv[2 * e] = vt
        vv[2 * e + 1] = nx * nx + ny * ny + nz * nz
        wn[a] = nx  # the wind at the midpoint is no longer needed
        wn[a + 1] = ny
        wn[a + 2] = nz
        ev[a] = ex
        ev[a + 1] = ey
        ev[a + 2] = ez


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def _element_views(p, w, n):
    """Per-element slots of the work array: the wind at the element midpoints (overwritten by
    the normal relative velocity v_n), the (v_t, |v_n|^2) pairs (overwritten by the drag
    factors), the unit vectors e."""
    WN = points_offset(n) + 3 * (n + 1 + int(p[P_NFIN]))
    S = scratch_offset(n)
    return w[WN:WN + 3 * n], w[S:S + 2 * n], w[S + 2 * n:S + 5 * n]


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def _element_drag(x, p, w, n):
    """Morison drag with loading functions, from the midpoint velocity v relative to the air:
    D = q |v|^2 [f_n(phi) (-v_n/|v_n|) + f_t(phi) (-sign(v.e) e)], phi in [0, pi/2] the angle
    between v and the element axis. Stores D = k_n v_n + k_t e as the two factors (k_n, k_t)."""
    o = aerostat_offset(n)
    l_u = x[o + S_LENGTH] / n
    qd = 0.5 * p[P_RHO] * p[P_CDN] * p[P_DIAM] * l_u
    f0, f1, f2, f3, f4 = p[P_FN], p[P_FN + 1], p[P_FN + 2], p[P_FN + 3], p[P_FN + 4]
    t0, t1, t2, t3, t4, t5 = p[P_FT], p[P_FT + 1], p[P_FT + 2], p[P_FT + 3], p[P_FT + 4], p[P_FT + 5]
    # in place on the (v_t, |v_n|^2) pairs; a view, so the indices are known non-negative
    # (no wraparound select) and the loop vectorizes
    vv = _element_views(p, w, n)[1]
    for e in range(n):
        vt = vv[2 * e]
        vn2 = vv[2 * e + 1]
        v2 = vt * vt + vn2
        at = abs(vt)
        vn = math.sqrt(vn2)
        ivm = 1.0 / max(math.sqrt(v2), 1e-150)
        c, s = at * ivm, vn * ivm
        r = _atan01(min(at, vn) / max(at, vn, 1e-150))
        phi = r if vn <= at else 0.5 * math.pi - r
        fn = f0 + f1 * c + f2 * s + f3 * (2.0 * c * c - 1.0) + f4 * 2.0 * s * c
        # f_t(phi) by Estrin's scheme (a reassociated Horner: shorter dependency chain)
        p2 = phi * phi
        ft = (t0 + phi * t1) + p2 * ((t2 + phi * t3) + p2 * (t4 + phi * t5))
        vv[2 * e] = -qd * v2 * fn / vn if vn > 0.0 else 0.0
        vv[2 * e + 1] = -qd * v2 * ft * (1.0 if vt > 0.0 else -1.0)


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def _node_forces(x, p, w, n):
    """Node forces: node j gets T e + D/2 from the element above it (j-1, of which it is the
    lower node) and -T e + D/2 from the element below (j), plus gravity (full node mass inside,
    half an element at the confluence point)."""
    o = aerostat_offset(n)
    g = p[P_MU] * x[o + S_LENGTH] / n * p[P_G]
    F, T0 = node_force_offset(n), tension_offset(n)
    frc, ten = w[F:T0], w[T0:T0 + n]
    vn, kk, ev = _element_views(p, w, n)
    ux = uy = uz = 0.0  # force on node j from element j-1 (none above node 0)
    for j in range(n + 1):
        fx, fy, fz = ux, uy, uz
        if j < n:
            a = 3 * j
            T, kn, kt = ten[j], kk[2 * j], kk[2 * j + 1]
            ex, ey, ez = ev[a], ev[a + 1], ev[a + 2]
            Dx = kn * vn[a] + kt * ex
            Dy = kn * vn[a + 1] + kt * ey
            Dz = kn * vn[a + 2] + kt * ez
            fx += -T * ex + 0.5 * Dx
            fy += -T * ey + 0.5 * Dy
            fz += -T * ez + 0.5 * Dz
            ux, uy, uz = T * ex + 0.5 * Dx, T * ey + 0.5 * Dy, T * ez + 0.5 * Dz
        frc[3 * j] = fx
        frc[3 * j + 1] = fy
        frc[3 * j + 2] = fz - (0.5 * g if j == 0 else g)


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def tether_forces(t, x, p, wp, wf, R, w):
    """Kinematics, winds, tensions and node forces; returns the winch-end element tension."""
    npts = _kinematics(x, p, R, w)
    wind_batch(t, w, npts, points_offset(int(p[P_NEL])), wp, wf)
    return _tether(x, p, w)


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def _hull(u, v, wv, p):
    """Jones & DeLaurier hull force (body) and nose moment vector from air-relative velocity.

    alpha = acos(u / V), crossflow Vc = sqrt(v^2 + w^2); lift opposes the crossflow:
    F = [-D_h, -L_h v / Vc, -L_h w / Vc]. L_h / Vc and M_nose / Vc are evaluated in closed form
    so alpha -> 0 has no 0/0. The nose moment (positive nose-up) acts about x_hat x lift_hat.
    """
    V2 = u * u + v * v + wv * wv
    if V2 < 1e-20:
        return 0.0, 0.0, 0.0, 0.0, 0.0
    V = math.sqrt(V2)
    iV = 1.0 / V
    q0 = 0.5 * p[P_RHO] * V2
    qV = q0 * iV  # q / V
    ca = u * iV
    sa = math.sqrt(v * v + wv * wv) * iV
    c2 = math.sqrt(max(0.0, 0.5 * (1.0 + ca)))  # cos(alpha/2)
    s2 = math.sqrt(max(0.0, 0.5 * (1.0 - ca)))  # sin(alpha/2)
    kp = p[P_KPOT]
    # drag along -x: axial friction (sign follows u) minus the axial part of the potential force
    D = q0 * (p[P_CD0H] * p[P_SH] * ca * abs(ca) - kp * p[P_I1] * 2.0 * sa * ca * s2)
    # lift and nose moment per unit crossflow speed (divide sin(alpha) by Vc = V sin(alpha))
    Lc = qV * (kp * p[P_I1] * 2.0 * ca * c2 + p[P_CDC] * p[P_J1] * sa)
    Mc = -qV * (kp * p[P_I3] * 2.0 * ca * c2 + p[P_CDC] * p[P_J2] * sa)
    # force components; moment about x_hat x lift_hat = (0, w, -v)/Vc, times M_nose
    return -D, -Lc * v, -Lc * wv, Mc * wv, -Mc * v


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def fin_coefficients(alpha, p):
    """Lift and drag coefficients (C_L, C_D) of a fin at local incidence alpha in [-pi, pi].

    Below the stall angle alpha_s: C_L = a alpha, C_D = C_D0 + k (a alpha)^2 (the paper's
    linear fin, so the trim and the linearization are [LN02]'s). Beyond it, with
    ``post_stall = 'viterna'``, the Viterna-Corrigan extrapolation (NASA CP-2230, 1982), matched
    to (C_L, C_D) at alpha_s so both are continuous there::

        C_L = A1 sin 2 alpha + A2 cos^2 alpha / sin alpha,  A1 = C_D,max / 2,
        A2 = (C_Ls - C_D,max sin alpha_s cos alpha_s) sin alpha_s / cos^2 alpha_s
        C_D = C_D,max sin^2 alpha + B2 cos alpha,  B2 = (C_Ds - C_D,max sin^2 alpha_s) / cos alpha_s

    so the normal force C_N = C_L cos alpha + C_D sin alpha grows to C_D,max at 90 deg, as a
    plate's does. Reverse flow (|alpha| > 90 deg) mirrors the plate: C_L(pi - alpha) = -C_L(alpha),
    C_D(pi - alpha) = C_D(alpha); C_L is odd and C_D even in alpha. With ``post_stall = 'flat'``
    C_L is held at +-a alpha_s and C_D keeps the unsaturated induced term ([LN02]'s rule).
    """
    a_st = p[P_ASTALL]
    cla = p[P_CLA]
    if p[P_POSTSTALL] == 0.0:
        return (cla * min(max(alpha, -a_st), a_st),
                p[P_CD0F] + cla * cla * alpha * alpha * p[P_KIND])
    aa = abs(alpha)
    reverse = aa > 0.5 * math.pi
    am = math.pi - aa if reverse else aa  # incidence from the nearer edge, in [0, pi/2]
    if am <= a_st:
        cl = cla * am
        cd = p[P_CD0F] + cl * cl * p[P_KIND]
    else:
        cdm = p[P_CDMAX]
        ss, cs = math.sin(a_st), math.cos(a_st)
        cls = cla * a_st
        cds = p[P_CD0F] + cls * cls * p[P_KIND]
        sa, ca = math.sin(am), math.cos(am)
        a2 = (cls - cdm * ss * cs) * ss / (cs * cs)
        b2 = (cds - cdm * ss * ss) / cs
        cl = cdm * sa * ca + a2 * ca * ca / sa
        cd = cdm * sa * sa + b2 * ca
    if reverse:
        cl = -cl
    return (cl if alpha >= 0.0 else -cl), cd


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def _fin(u, v, wv, p, i):
    """Lift and drag of fin i (body frame) from its air-relative velocity (u, v, w)."""
    b = P_FIN + 9 * i
    nx, ny, nz = p[b + 6], p[b + 7], p[b + 8]
    un = u  # chordwise component (body x)
    wn = u * nx + v * ny + wv * nz  # normal to the fin plane
    V2 = u * u + v * v + wv * wv
    if V2 < 1e-20:
        return 0.0, 0.0, 0.0
    alpha = fast_atan2(wn, un)
    cl, cd = fin_coefficients(alpha, p)
    q = 0.5 * p[P_RHO] * p[P_AF] * V2
    qin = math.sqrt(un * un + wn * wn)
    fx = fy = fz = 0.0
    if qin > 1e-12:
        # lift perpendicular to the in-plane velocity, against the crossflow:
        # F_L = L (sin(alpha) x_hat - cos(alpha) n_hat)
        iq = 1.0 / qin
        sal, cal = wn * iq, un * iq
        lift = q * cl
        fx += lift * sal - lift * cal * nx
        fy += -lift * cal * ny
        fz += -lift * cal * nz
    # drag opposes the full 3-D air-relative velocity (spanwise flow included, as in [LN02])
    kd = -q * cd / math.sqrt(V2)
    return fx + kd * u, fy + kd * v, fz + kd * wv


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, _nrt=False)
def rhs(t, x, u, p, wp, wf, dx, w):
    """State derivative dx = f(t, x, u) of the full model (see module docstring).

    Parameters
    ----------
    t : float, time [s]. x : state (layout in :mod:`aerostat_gym.physics.state`).
    u : [reel-out speed set-point (m/s), brake flag]. p : packed parameters.
    wp, wf : wind parameter vector and turbulence field (:mod:`aerostat_gym.physics.wind`).
    dx : output array, same size as x. w : work array of ``work_size(n)`` floats; on return it
    holds node positions, velocities, forces and element tensions.

    Compiled without reference counting (``_nrt=False``): it only reads and writes the arrays
    it is given, and the atomic increments cost more than the tether. The aerostat's
    aerodynamic loads come first: they do not depend on the tether, so the processor works on
    them while the tether's square roots and divisions are in flight.
    """
    n = int(p[P_NEL])
    nm = n - 1
    o = aerostat_offset(n)
    R = _rotation(x[o + S_PHI], x[o + S_THETA], x[o + S_PSI])
    npts = _kinematics(x, p, R, w)
    wind_batch(t, w, npts, points_offset(n), wp, wf)
    loads = _aero_loads(t, x, p, wp, wf, w, R, o)
    Tw = _tether(x, p, w)
    F = node_force_offset(n)
    # moving nodes: position' = velocity, velocity' = force / node mass (views: no wraparound)
    im_node = n / (p[P_MU] * x[o + S_LENGTH])
    xv, dxp, dxv, frc = x[3 * nm:6 * nm], dx[:3 * nm], dx[3 * nm:6 * nm], w[F + 3:F + 3 * n]
    for i in range(3 * nm):
        dxp[i] = xv[i]
        dxv[i] = frc[i] * im_node
    _aerostat(x, p, R, loads, w[F], w[F + 1], w[F + 2], dx, o)
    if p[P_FIXED] != 0.0:
        for k in range(12):
            dx[o + k] = 0.0
    _winch(x, u, p, Tw, dx, o)


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def _aero_loads(t, x, p, wp, wf, w, R, o):
    """Body-frame force and moment about the CM of everything on the aerostat except the
    tether: weight at the CM, buoyancy at the CB, hull and fins (winds at the hull and fin
    points are read from the work array), and the air-inertia force at the CB when the air
    accelerates."""
    n = int(p[P_NEL])
    nf = int(p[P_NFIN])
    vx, vy, vz = x[o + S_VX], x[o + S_VY], x[o + S_VZ]
    pp, qq, rr = x[o + S_P], x[o + S_Q], x[o + S_R]
    # body components of the CM velocity
    ub = R[0] * vx + R[3] * vy + R[6] * vz
    vb = R[1] * vx + R[4] * vy + R[7] * vz
    wb = R[2] * vx + R[5] * vy + R[8] * vz
    g, m, B = p[P_G], p[P_MASS], p[P_BUOY]
    # body components of inertial up (z_hat)
    zx, zy, zz = R[6], R[7], R[8]
    # gravity at the CM, buoyancy at the CB
    Fx = (B - m * g) * zx
    Fy = (B - m * g) * zy
    Fz = (B - m * g) * zz
    xb, yb, zb = p[P_CB], p[P_CB + 1], p[P_CB + 2]
    Mx = yb * B * zz - zb * B * zy
    My = zb * B * zx - xb * B * zz
    Mz = xb * B * zy - yb * B * zx
    # hull: air-relative velocity at the centre of buoyancy (the hull's volume centroid)
    WA = points_offset(n) + 3 * (2 * n + 1 + nf)  # wind at the hull point, then at each fin
    hx, hy, hz = _air_body(ub, vb, wb, pp, qq, rr, xb, yb, zb, R, w[WA], w[WA + 1], w[WA + 2])
    hfx, hfy, hfz, hmy, hmz = _hull(hx, hy, hz, p)
    xn, yn, zn = p[P_NOSE], p[P_NOSE + 1], p[P_NOSE + 2]
    Fx += hfx
    Fy += hfy
    Fz += hfz
    Mx += yn * hfz - zn * hfy
    My += zn * hfx - xn * hfz + hmy
    Mz += xn * hfy - yn * hfx + hmz
    for i in range(nf):
        b = P_FIN + 9 * i
        cx, cy, cz = p[b], p[b + 1], p[b + 2]
        k = WA + 3 * (i + 1)
        fu, fv, fw = _air_body(ub, vb, wb, pp, qq, rr, cx, cy, cz, R, w[k], w[k + 1], w[k + 2])
        ffx, ffy, ffz = _fin(fu, fv, fw, p, i)
        Fx, Fy, Fz, Mx, My, Mz = _add_load(Fx, Fy, Fz, Mx, My, Mz, cx, cy, cz, ffx, ffy, ffz)
    if p[P_AIRINERTIA] != 0.0 and (wp[W_GUST_ON] != 0.0 or (wp[W_TURB_ON] != 0.0 and wf.shape[1] > 1)):
        hp = points_offset(n) + 3 * n  # the hull point (centre of buoyancy), inertial
        aix, aiy, aiz = air_inertia_load(t, w[hp], w[hp + 1], w[hp + 2], p, R, wp, wf)
        Fx, Fy, Fz, Mx, My, Mz = _add_load(Fx, Fy, Fz, Mx, My, Mz, xb, yb, zb, aix, aiy, aiz)
    return Fx, Fy, Fz, Mx, My, Mz


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def air_inertia_load(t, px, py, pz, p, R, wp, wf):
    """Body-frame force of accelerating air on the hull at inertial point (px, py, pz).

    The pressure gradient that accelerates the air at a = dW/dt (averaged over the hull's
    length along the wind) pushes the displaced volume with rho V a (Froude-Krylov); the air
    the hull must accelerate with it adds k_i rho V a_i along body axis i (added mass; the
    body's own acceleration is in the effective mass). In total
    F_i = (rho V + m_a,i) a_i = (1 + k_i) rho V a_i, with rho V = B / g.
    """
    ax, ay, az = air_acceleration(px, py, pz, t, wp, wf, p[P_AILEN])
    # body components R^T a
    abx = R[0] * ax + R[3] * ay + R[6] * az
    aby = R[1] * ax + R[4] * ay + R[7] * az
    abz = R[2] * ax + R[5] * ay + R[8] * az
    rv = p[P_BUOY] / p[P_G]
    return (rv + p[P_MA]) * abx, (rv + p[P_MA + 1]) * aby, (rv + p[P_MA + 2]) * abz


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def _add_load(Fx, Fy, Fz, Mx, My, Mz, cx, cy, cz, fx, fy, fz):
    """Add a force (fx, fy, fz) acting at body point (cx, cy, cz): F += f, M += c x f."""
    return (Fx + fx, Fy + fy, Fz + fz, Mx + (cy * fz - cz * fy), My + (cz * fx - cx * fz),
            Mz + (cx * fy - cy * fx))


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def _aerostat(x, p, R, loads, flx, fly, flz, dx, o):
    """Aerostat rigid-body derivatives from the non-tether loads (body frame, about the CM) and
    (flx, fly, flz), the tether force at the leash point (inertial)."""
    R00, R01, R02, R10, R11, R12, R20, R21, R22, cph, sph, cth, sth = R
    Fx, Fy, Fz, Mx, My, Mz = loads
    icth = 1.0 / cth
    vx, vy, vz = x[o + S_VX], x[o + S_VY], x[o + S_VZ]
    pp, qq, rr = x[o + S_P], x[o + S_Q], x[o + S_R]
    # body components of the CM velocity
    ub = R00 * vx + R10 * vy + R20 * vz
    vb = R01 * vx + R11 * vy + R21 * vz
    wb = R02 * vx + R12 * vy + R22 * vz
    # tether at the leash point
    xl, yl, zl = p[P_LEASH], p[P_LEASH + 1], p[P_LEASH + 2]
    fbx = R00 * flx + R10 * fly + R20 * flz
    fby = R01 * flx + R11 * fly + R21 * flz
    fbz = R02 * flx + R12 * fly + R22 * flz
    Fx, Fy, Fz, Mx, My, Mz = _add_load(Fx, Fy, Fz, Mx, My, Mz, xl, yl, zl, fbx, fby, fbz)
    # Kirchhoff inertial terms: M_e a_B = F + M_a (omega x V) - omega x (M_a V)
    max_, may, maz = p[P_MA], p[P_MA + 1], p[P_MA + 2]
    ox, oy, oz = qq * wb - rr * vb, rr * ub - pp * wb, pp * vb - qq * ub  # omega x V
    Pax, Pay, Paz = max_ * ub, may * vb, maz * wb  # M_a V
    gx = max_ * ox - (qq * Paz - rr * Pay)
    gy = may * oy - (rr * Pax - pp * Paz)
    gz = maz * oz - (pp * Pay - qq * Pax)
    abx = (Fx + gx) / p[P_ME]
    aby = (Fy + gy) / p[P_ME + 1]
    abz = (Fz + gz) / p[P_ME + 2]
    for k in range(3):
        dx[o + k] = x[o + S_VX + k]
    dx[o + S_VX] = R00 * abx + R01 * aby + R02 * abz
    dx[o + S_VY] = R10 * abx + R11 * aby + R12 * abz
    dx[o + S_VZ] = R20 * abx + R21 * aby + R22 * abz
    # rotation: I domega = M - omega x (I omega) - V x (M_a V)
    I = P_INERTIA
    Lx = p[I] * pp + p[I + 1] * qq + p[I + 2] * rr
    Ly = p[I + 3] * pp + p[I + 4] * qq + p[I + 5] * rr
    Lz = p[I + 6] * pp + p[I + 7] * qq + p[I + 8] * rr
    Mx -= qq * Lz - rr * Ly + (vb * Paz - wb * Pay)
    My -= rr * Lx - pp * Lz + (wb * Pax - ub * Paz)
    Mz -= pp * Ly - qq * Lx + (ub * Pay - vb * Pax)
    J = P_IINV
    dx[o + S_P] = p[J] * Mx + p[J + 1] * My + p[J + 2] * Mz
    dx[o + S_Q] = p[J + 3] * Mx + p[J + 4] * My + p[J + 5] * Mz
    dx[o + S_R] = p[J + 6] * Mx + p[J + 7] * My + p[J + 8] * Mz
    # Z-Y-X Euler kinematics
    tth = sth * icth
    dx[o + S_PHI] = pp + (qq * sph + rr * cph) * tth
    dx[o + S_THETA] = qq * cph - rr * sph
    dx[o + S_PSI] = (qq * sph + rr * cph) * icth


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def _air_body(ub, vb, wb, pp, qq, rr, cx, cy, cz, R, ax, ay, az):
    """Body-frame velocity relative to the air of the body point c: V + omega x c - R^T W,
    with W = (ax, ay, az) the inertial air velocity at that point."""
    R00, R01, R02, R10, R11, R12, R20, R21, R22 = R[0], R[1], R[2], R[3], R[4], R[5], R[6], R[7], R[8]
    u = ub + qq * cz - rr * cy - (R00 * ax + R10 * ay + R20 * az)
    v = vb + rr * cx - pp * cz - (R01 * ax + R11 * ay + R21 * az)
    w = wb + pp * cy - qq * cx - (R02 * ax + R12 * ay + R22 * az)
    return u, v, w


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def _winch(x, u, p, Tw, dx, o):
    """Winch: L' = v_w; speed loop v_w' = clip((v_s - v_w)/tau, +-a_max) realised by a motor
    force on the reflected drivetrain m_eq v_w' = T + F_m - F_c tanh(v_w/v_f) - c_v v_w with
    |F_m| <= F_max, so the force limit (not the formula) decides when the loop loses authority.
    The brake (u[1] != 0) holds the drum: both derivatives zero (the Python-side controller,
    :mod:`aerostat_gym.sim.winch`, brings v_w to zero before it engages the brake).

    v_s is the set-point clipped to +-v_max and then capped near the length limits by the
    stopping profile v_cap(d) = min(d / (4 tau), sqrt(a_max d)), d the distance to the limit.
    The square-root part decelerates at a_max / 2, leaving the other half to the lag; the linear
    part makes the closed loop critically damped at the limit (tau d'' + d' + d / (4 tau) = 0),
    so the drum stops at the limit without overshoot when the motor has authority.

    Over-hauled (the motor force saturated), the drum speed never exceeds what the set-point
    may ask for: the rated speed v_max, and near a length limit the stopping profile's v_cap.
    The brake takes whatever the motor cannot, so that v_w' stays within
    ((-v_lo - v_w) / tau, (v_hi - v_w) / tau), v_hi and v_lo the pay-out and reel-in speeds
    the set-point is clipped to, the bound the unsaturated speed loop obeys anyway; the drum
    then follows the same critically damped approach and stops at the limit, and a drum found
    beyond the bound returns to it. (Without the profile in this bound, a load that over-hauls
    the motor near max_length ran the drum past it at up to v_max.) The holding brake that
    stops an over-hauled drum against a reel-in or hold command is supervisory
    (:func:`aerostat_gym.sim.winch.brake_rule`): it arrives here as u[1] != 0.
    """
    L, v = x[o + S_LENGTH], x[o + S_REEL]
    if u[1] != 0.0:
        dx[o + S_LENGTH] = 0.0
        dx[o + S_REEL] = 0.0
        return
    vmax, a_max, tau = p[P_W_VMAX], p[P_W_AMAX], p[P_W_TAU]
    d_hi = max(p[P_W_LMAX] - L, 0.0)
    d_lo = max(L - p[P_W_LMIN], 0.0)
    v_hi = min(vmax, d_hi / (4.0 * tau), math.sqrt(a_max * d_hi))
    v_lo = min(vmax, d_lo / (4.0 * tau), math.sqrt(a_max * d_lo))
    vs = min(max(u[0], -v_lo), v_hi)
    a_des = min(max((vs - v) / tau, -a_max), a_max)
    m_eq = p[P_W_MEQ]
    fr = winch_friction(v, p)
    Fm = min(max(m_eq * a_des - Tw + fr, -p[P_W_FMAX]), p[P_W_FMAX])
    dv = (Tw + Fm - fr) / m_eq
    if abs(Fm) >= p[P_W_FMAX]:
        # motor saturated: the brake takes what the motor cannot, so the drum approaches the
        # set-point's speed bound no faster than the speed loop would (never beyond it)
        dv = min(max(dv, (-v_lo - v) / tau), (v_hi - v) / tau)
    dx[o + S_LENGTH] = v
    dx[o + S_REEL] = dv


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def winch_friction(v, p):
    """Drivetrain friction at the line [N] for reel speed v: Coulomb, smoothed as
    F_c tanh(v / v_f) so the speed loop stays differentiable through v = 0, plus viscous c_v v."""
    return p[P_W_FC] * math.tanh(v / p[P_W_FRICTION_V]) + p[P_W_CV] * v


@njit(cache=True, error_model="numpy", fastmath=FASTMATH)
def evaluate_tether(t, x, p, wp, wf, w):
    """Fill the work array (node kinematics, forces, tensions) for state x; returns the
    winch-end element tension. Used for outputs; :func:`rhs` does the same internally."""
    o = aerostat_offset(int(p[P_NEL]))
    R = _rotation(x[o + S_PHI], x[o + S_THETA], x[o + S_PSI])
    return tether_forces(t, x, p, wp, wf, R, w)
