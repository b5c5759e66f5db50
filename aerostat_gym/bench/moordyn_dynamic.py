"""Dynamic peer comparison with MoorDyn v2 (issue 20): the tether in motion, top end driven.

The static comparison (:mod:`aerostat_gym.bench.moordyn`) holds the top end fixed; here the top end
follows a prescribed path from the settled trim shape and the two codes' node positions and end
tensions are compared sample by sample. Same line, same fluid and the same drag model choices as
the static comparison: one line of n = 10 segments in air (rho = 1.225), the steady uniform
10 m/s "current" standing in for the wind, MoorDyn's line 100 m below its water surface (frame
shift, undone for the comparison), BA = b, Cd = Cd_normal, CdAx = Cd_normal f_t(0) / pi,
Ca = CaAx = 0, EI = 0 (see :mod:`aerostat_gym.bench.moordyn` for why each).

Cases (:func:`standard_cases`)
------------------------------
- Sinusoidal top motion r_top(t) = r_trim + A sin(2 pi t / T) d_hat from t = 0, d_hat along the
  wind (+X), across it (+Y) and vertical (+Z), T the longitudinal pendulum period, the first
  tether harmonic and the axial spring period of :func:`aerostat_gym.analysis.reference
  .reference_periods` (41.0 s, 1.68 s, 3.00 s at rho = 1.225), A = 1 m and 5 m. Compared over the
  60 s after the first cycle.
- Reel: the unstretched length grows at 1 m/s for 10 s (paid out, top end held). MoorDyn 2.7 has
  the API: ``SetLineUnstretchedLength`` / ``SetLineUnstretchedLengthVel`` (C:
  ``MoorDyn_SetLineUnstretchedLength[Vel]``); with a rate set, each Step ramps the length
  linearly, L = L_step_start + t_local Ldot, and every segment's l = L / N and the node masses and
  volumes follow (``Line::setUnstretchedLength``, ``Line::updateUnstretchedLength``). Reeling
  *in* 10 m with the top end held would stretch the line by 10 m (~35 kN, the tether's
  strength), so the length is paid out. Compared over 60 s from the start.
- Drop: the top end falls 20 m in 2 s (cosine ramp, up to 15.7 m/s, faster than the line falls
  in air), is held 3 s and rises back in 4 s (up to 7.9 m/s): the line goes slack and snaps taut
  again. Compared over 60 s from the start.

How the top end is driven
-------------------------
- Ours: the tether-only model (``Model(..., fixed_aerostat=True)``, the aerostat's derivatives
  are zeroed) with the aerostat's CM position and velocity overwritten before every right-hand
  side evaluation so that the confluence point (CM + R r_l, the attitude held at the trim, rates
  zero) sits on the path: :func:`driven_rk4` at every RK4 stage time (the path's exact position
  and velocity), :func:`driven_si` before every semi-implicit step (position at the step start,
  the secant velocity over the step, which is what that scheme's position update
  x_{k+1} = x_k + h v_{k+1} needs for the top to land on the path). For the reel case the
  unstretched length L and its rate (the winch states, braked so the core leaves them alone) are
  overwritten the same way.
- MoorDyn: point 2 is ``Coupled``; every Step call of one MoorDyn time step h gives it the path
  position at the step start and the secant velocity, and MoorDyn moves it linearly within the
  step (``Point::updateFairlead``: r = r_start + rd t_local), so it is on the path at every step
  boundary.

Both codes first settle for ``settle`` seconds with the top end at the trim (MoorDyn from its own
still-fluid initial state, ours from the straight chord with RK4, the start of both our
integrators, as in the static comparison); the drive starts at t = 0 after that.

Time steps
----------
Outputs every 0.05 s. Ours: RK4 at h = 0.05 / 9 = 5.56 ms (0.86 x its axial stability bound at
300 m), semi-implicit at ``simulation.semi_implicit_dt`` = 0.05 s. MoorDyn RK4 (the reference) at
0.05 / 18 = 2.78 ms, and checked converged by a second run at half that step (its difference
from the reference is reported per case: ``moordyn_step_check``).

Figures
-------
Over each case's window, for each of our integrators against MoorDyn: node positions (the n - 1
free nodes) RMS and max distance as % of L; top and bottom tension RMS difference as % of
MoorDyn's mean tension over the window, and the phase lag (positive: ours lags) of the harmonic
of the drive period (first or second, whichever dominates MoorDyn's tension: motion across the
wind swings the tension at twice the drive frequency) from a least-squares fit (sinusoidal
cases) or from the peak of the cross-correlation (reel, drop); the slack segments (stretched length <= unstretched, the
definition shared by both codes' elastic law) of each code; the wall time of each code for the
whole case (drive plus window, best of ``repeats``, the settle excluded) and the speed ratio
MoorDyn wall / ours wall. MoorDyn's wall time includes one Python Step call per MoorDyn step
(that is how a coupled top end is driven with its Python API).

Named modelling differences and their switches (``variant`` of :func:`prepare`)
-------------------------------------------------------------------------------
- ``"crossflow_drag"`` (drag law only): ours with f_n(phi) = sin^2 phi (loading_fn = [0.5, 0,
  0, -0.5, 0]) and f_t = 0, MoorDyn with CdAx = 0: the same crossflow law on both sides, our
  element-midpoint lumping kept.
- ``"moordyn_drag"`` (drag law and lumping, our side): MoorDyn's nodal drag
  (:func:`moordyn_node_drag`: each node's own velocity and the tangent through its neighbours,
  Cd sin^2 and CdAx cos^2) replaces ours (loading functions on each element's midpoint
  velocity, half to each end node) in the node accelerations (:func:`_apply_moordyn_drag`).
- ``"no_buoyancy"`` (buoyancy, MoorDyn's side): its line mass per length raised by
  rho_air A, so its submerged weight equals our weight (its inertia rises by 0.15 %).
- ``"moordyn_slack_rule"`` (damping clip, our side): MoorDyn's segment force
  (:func:`moordyn_segment_tension`: the elastic part only when stretched, the dashpot always, so
  it can push, and no unstretched-length rate in the strain rate) replaces our tension-only
  T = max(EA eps + c* deps/dt, 0).
- ``"moordyn_drag_and_slack_rule"``: both of ours together: the two codes then integrate the
  same equations and what is left is time discretization.
- ``"no_damping"``: internal damping off in both codes (BA = b = 0), another way to remove the
  clip; the undamped snap loads are then far from converged in either code, so it is not used
  for the explanations.

The our-side switches act in :func:`driven_rk4` only (the semi-implicit step has no such hook;
its columns stay the unswitched scheme). With MoorDyn's drag switched in, the smoke case (no
slack) agrees to 0.002 % of the mean tension.
"""

from __future__ import annotations

import ctypes
import math
import os
import tempfile
import time
from dataclasses import dataclass

import numpy as np
from numba import njit

from ..analysis.reference import reference_periods
from ..analysis.trim import find_equilibrium
from ..params import Params, load_params
from ..physics.core import rhs
from ..physics.integrators import NONFINITE, OK, all_finite, si_advance
from ..physics.packing import P_CDN, P_DASHPOT, P_DIAM, P_EA, P_G, P_MU, P_NEL, P_RHO
from ..physics.state import (
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
from ..sim import BRAKED, Model
from .moordyn import (
    RHO_AIR,
    SUBMERGENCE,
    WIND,
    _captured_c_output,
    _chord_state,
    _import_moordyn,
    _tail,
    _version,
    axial_cdt,
    current_profile,
    moordyn_input,
)

OUTPUT_DT = 0.05  # s between compared samples (= the semi-implicit step)
RK4_SUBSTEPS = 9  # our RK4 steps per output interval: h = 5.56 ms
MOORDYN_SUBSTEPS = 18  # MoorDyn RK4 steps per output interval: h = 2.78 ms
WINDOW = 60.0  # s compared
SETTLE = 30.0  # s with the top end held at the trim before the drive starts
POSITION_TARGET_PCT = 0.5  # issue 20: node positions within 0.5 % of L (max over the window)
TENSION_TARGET_PCT = 2.0  # issue 20: tensions within 2 % RMS of the mean tension
VARIANTS = ("baseline", "crossflow_drag", "moordyn_drag", "no_buoyancy", "moordyn_slack_rule",
            "moordyn_drag_and_slack_rule", "no_damping")
#: our-side switches (bits of the swap vector's flags) per variant
_SWAPS = {"moordyn_drag": 2, "moordyn_slack_rule": 1, "moordyn_drag_and_slack_rule": 3}
DIRECTIONS = {"along": (1.0, 0.0, 0.0), "across": (0.0, 1.0, 0.0), "vertical": (0.0, 0.0, 1.0)}

# path kinds and the packed path vector (read by the compiled drivers)
SINE, DROP, REEL = 0, 1, 2
K_KIND, K_TOP, K_DIR, K_LEVER = 0, 1, 4, 7  # kind; trim top end (3); direction (3); CM - top (3)
K_AMP, K_OMEGA = 10, 11  # sine: amplitude [m], angular frequency [rad/s]
K_L0, K_REEL_V, K_REEL_T = 12, 13, 14  # reel: initial length [m], rate [m/s], duration [s]
K_DROP_D, K_DROP_T, K_HOLD_T, K_RISE_T = 15, 16, 17, 18  # drop: depth [m], fall, hold, rise [s]
PATH_SIZE = 19
# the aerostat block of the state, named once in aerostat_gym.physics.state
CM_POS, CM_VEL, RATES, LENGTH, LENGTH_RATE = S_X, S_VX, S_P, S_LENGTH, S_REEL


class DynamicBenchError(ValueError):
    """Invalid input to the dynamic comparison (unknown case, variant or bad option)."""


# --- the prescribed path ---------------------------------------------------------------------


@dataclass(frozen=True)
class DrivenCase:
    """One prescribed top-end motion (see the module docstring).

    Parameters
    ----------
    name : str
        Label in the table.
    kind : int
        ``SINE``, ``DROP`` or ``REEL``.
    direction : tuple of float
        Unit vector of the sinusoidal motion (inertial; +X along the wind, +Z up).
    amplitude : float
        Sine amplitude [m].
    period : float
        Sine period [s].
    reel_speed : float
        Rate of change of the unstretched length [m/s] (positive pays out).
    reel_time : float
        Duration of the length change [s].
    drop_depth : float
        Depth of the vertical drop [m].
    drop_time : float
        Duration of the fall [s].
    hold_time : float
        Time held at the bottom [s].
    rise_time : float
        Duration of the rise back to the trim [s].
    window : float
        Length of the compared window [s].
    """

    name: str
    kind: int
    direction: tuple = (0.0, 0.0, 1.0)
    amplitude: float = 0.0
    period: float = 0.0
    reel_speed: float = 0.0
    reel_time: float = 0.0
    drop_depth: float = 0.0
    drop_time: float = 0.0
    hold_time: float = 0.0
    rise_time: float = 0.0
    window: float = WINDOW

    @property
    def window_start(self) -> float:
        """Start of the compared window [s]: after the first cycle of a sine, else 0."""
        return self.period if self.kind == SINE else 0.0

    @property
    def duration(self) -> float:
        """Simulated time from the start of the drive to the end of the window [s]."""
        return self.window_start + self.window

    def pack(self, top: np.ndarray, lever: np.ndarray, length: float) -> np.ndarray:
        """Path vector for the compiled drivers.

        Parameters
        ----------
        top : ndarray
            Trim position of the top end (confluence point) [m].
        lever : ndarray
            CM minus confluence point at the trim attitude [m].
        length : float
            Unstretched length at the start [m].
        """
        v = np.zeros(PATH_SIZE)
        v[K_KIND] = self.kind
        v[K_TOP:K_TOP + 3] = top
        v[K_DIR:K_DIR + 3] = np.asarray(self.direction, float) / np.linalg.norm(self.direction)
        v[K_LEVER:K_LEVER + 3] = lever
        v[K_AMP] = self.amplitude
        v[K_OMEGA] = 2.0 * math.pi / self.period if self.period > 0 else 0.0
        v[K_L0] = length
        v[K_REEL_V], v[K_REEL_T] = self.reel_speed, self.reel_time
        v[K_DROP_D], v[K_DROP_T] = self.drop_depth, self.drop_time
        v[K_HOLD_T], v[K_RISE_T] = self.hold_time, self.rise_time
        return v


def standard_cases(params: Params) -> list[DrivenCase]:
    """The issue's table: 3 directions x 3 periods x 2 amplitudes, the reel and the drop."""
    ref = reference_periods(params)
    periods = {"pendulum": ref["long_pendulum"], "harmonic": ref["tether_1st"],
               "axial": ref["axial_spring"]}
    cases = [DrivenCase(f"{d}-{pn}-{a:g}m", SINE, DIRECTIONS[d], float(a), float(T))
             for d in DIRECTIONS for pn, T in periods.items() for a in (1.0, 5.0)]
    cases.append(DrivenCase("reel-out-1m/s-10s", REEL, reel_speed=1.0, reel_time=10.0))
    cases.append(drop_case())
    return cases


def drop_case() -> DrivenCase:
    """The slack case: a 20 m vertical drop in 2 s, held 3 s, back up in 4 s."""
    return DrivenCase("drop-20m-slack", DROP, drop_depth=20.0, drop_time=2.0, hold_time=3.0,
                      rise_time=4.0)


@njit(cache=True)
def _cosine_ramp(distance, duration, tau):
    """Displacement and rate of a cosine ramp over ``distance`` in ``duration`` at time tau."""
    a = math.pi / duration
    return 0.5 * distance * (1.0 - math.cos(a * tau)), 0.5 * distance * a * math.sin(a * tau)


@njit(cache=True)
def path_displacement(path, t):
    """Displacement of the top end along the path direction and its rate at time t (0 before
    the drive starts): s, ds/dt [m, m/s]."""
    if t <= 0.0:
        return 0.0, 0.0
    kind = int(path[K_KIND])
    if kind == SINE:
        w = path[K_OMEGA]
        return path[K_AMP] * math.sin(w * t), path[K_AMP] * w * math.cos(w * t)
    if kind == DROP:
        D, t1 = path[K_DROP_D], path[K_DROP_T]
        t2 = t1 + path[K_HOLD_T]
        t3 = t2 + path[K_RISE_T]
        if t < t1:
            s, sd = _cosine_ramp(D, t1, t)
            return -s, -sd
        if t < t2:
            return -D, 0.0
        if t < t3:
            s, sd = _cosine_ramp(D, path[K_RISE_T], t - t2)
            return s - D, sd
    return 0.0, 0.0


@njit(cache=True)
def path_length(path, t):
    """Unstretched length and its rate at time t [m, m/s] (constant except for the reel)."""
    if int(path[K_KIND]) != REEL or t <= 0.0:
        return path[K_L0], 0.0
    tr = min(t, path[K_REEL_T])
    return path[K_L0] + path[K_REEL_V] * tr, path[K_REEL_V] if t < path[K_REEL_T] else 0.0


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
def _unit(w, i, j):
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
    qx, qy, qz, _ = _unit(w, i1, i0)
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
        ex, ey, ez, _ = _unit(w, j - 1, j)
        T = w[T0 + j - 1]
        fx, fy, fz = fx - T * ex, fy - T * ey, fz - T * ez
    if j < n:
        ex, ey, ez, _ = _unit(w, j, j + 1)
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


# --- our side --------------------------------------------------------------------------------


def _variant_params(variant: str) -> tuple[Params, Params, float | None]:
    """(our parameters, MoorDyn's parameters, MoorDyn's mass per length or None) of a variant."""
    if variant not in VARIANTS:
        raise DynamicBenchError(f"unknown variant {variant!r}; choose one of {VARIANTS}")
    base = {"environment.rho_air": RHO_AIR}
    if variant == "crossflow_drag":
        base |= {"tether.loading_fn": [0.5, 0.0, 0.0, -0.5, 0.0],
                 "tether.loading_ft": [0.0] * 6}
    if variant == "no_damping":
        base |= {"tether.damping_ratio": 0.0}
    p = load_params(overrides=base)
    mass = None
    if variant == "no_buoyancy":
        mass = p.derived.mass_per_length + RHO_AIR * p.derived.tether_area
    return p, p, mass


@dataclass
class _Setup:
    """The shared starting point of a variant: parameters, trim top end, our settled state."""

    params: Params
    md_params: Params
    md_mass: float | None
    swap: np.ndarray
    model: Model
    top: np.ndarray
    lever: np.ndarray
    x_settled: np.ndarray
    settle: float


def prepare(variant: str = "baseline", settle: float = SETTLE) -> _Setup:
    """Parameters of ``variant``, the trim top end at U = 10 m/s and our tether settled there.

    Parameters
    ----------
    variant : str
        One of ``VARIANTS``.
    settle : float
        Seconds our tether settles (RK4, top end held) from the straight chord [s].
    """
    if not (math.isfinite(settle) and settle > 0):
        raise DynamicBenchError(f"settle must be finite and > 0 s, got {settle!r}")
    p, pmd, mass = _variant_params(variant)
    eq = find_equilibrium(p, WIND)
    model = Model(p, wind=WIND, fixed_aerostat=True)
    lay = model.layout
    top = model.node_positions(eq.x)[0]
    lever = eq.x[lay.cm_pos] - top
    x = _chord_state(model, eq.x)
    h = OUTPUT_DT / RK4_SUBSTEPS
    hold = DrivenCase("hold", SINE, period=1.0).pack(top, lever, p.tether.length)
    swap = np.array([_SWAPS.get(variant, 0), WIND, 0.0, 0.0, axial_cdt(pmd)])
    if driven_rk4(x, -settle, h, round(settle / h), hold, BRAKED, model.p, model.wp, model.wf,
                  model.work, swap) != OK:
        raise RuntimeError("our tether did not settle at the trim (non-finite state)")
    return _Setup(p, pmd, mass, swap, model, top, lever, x, settle)


def _end_tensions(model: Model, x: np.ndarray, swap: np.ndarray) -> tuple[float, float]:
    """Top and bottom tension (:meth:`Model.end_tensions`), with the end elements' axial force
    and the top node's drag from MoorDyn's rules where ``swap`` asks."""
    flags = int(swap[0])
    if not flags:
        return model.end_tensions(x)
    w = model._forces(x)
    n, p = model.n, model.p
    T0, F = tension_offset(n), node_force_offset(n)
    top = w[F:F + 3].copy()
    T_bot, e_bot = w[T0 + n - 1], np.array(_unit(w, n - 1, n)[:3])
    if flags & SWAP_SEGMENT_RULE:
        T_top, *e_top = moordyn_segment_tension(x, p, w, 0)
        top -= (T_top - w[T0]) * np.array(e_top)
        T_bot, *e_bot = moordyn_segment_tension(x, p, w, n - 1)
    if flags & SWAP_NODAL_DRAG:
        top += np.array(moordyn_node_drag(x, p, w, 0, swap)) - np.array(our_node_drag(x, p, w, 0))
    half_weight = 0.5 * model.params.derived.mass_per_length * x[model.layout.winch_length] / n
    bottom = T_bot * np.asarray(e_bot) - np.array([0.0, 0.0, half_weight * model.params.environment.g])
    return float(np.linalg.norm(top)), float(np.linalg.norm(bottom))


def _segment_slack(nodes: np.ndarray, length: float) -> int:
    """Number of segments whose stretched length is at most the unstretched one."""
    seg = np.linalg.norm(np.diff(nodes, axis=0), axis=1)
    return int(np.count_nonzero(seg <= length / (len(nodes) - 1)))


def _run_ours(setup: _Setup, path: np.ndarray, case: DrivenCase, integrator: str,
              repeats: int) -> dict:
    """Our driven run sampled every OUTPUT_DT, and its best wall time (no outputs) over the
    whole case."""
    m = setup.model
    fn, nsub = ((driven_rk4, RK4_SUBSTEPS) if integrator == "rk4"
                else (driven_si, max(1, round(OUTPUT_DT / setup.params.simulation.semi_implicit_dt))))
    h = OUTPUT_DT / nsub
    n_out = round(case.duration / OUTPUT_DT)
    x = setup.x_settled.copy()
    o = m.layout.cm_pos.start
    swap = setup.swap if integrator == "rk4" else NO_SWAP
    args = (BRAKED, m.p, m.wp, m.wf, m.work, swap)
    nodes, top, bottom, slack = [], [], [], []
    for k in range(n_out + 1):
        if k > 0 and fn(x, (k - 1) * OUTPUT_DT, h, nsub, path, *args) != OK:
            raise RuntimeError(f"our {integrator} run of {case.name!r} became non-finite "
                               f"at t = {k * OUTPUT_DT:.2f} s")
        pos = m.node_positions(x)
        nodes.append(pos)
        top_t, bot_t = _end_tensions(m, x, swap)
        top.append(top_t)
        bottom.append(bot_t)
        slack.append(_segment_slack(pos, x[o + LENGTH]))
    walls = []
    for _ in range(repeats):
        y = setup.x_settled.copy()
        t0 = time.perf_counter()
        fn(y, 0.0, h, nsub * n_out, path, *args)
        walls.append(time.perf_counter() - t0)
    return {"nodes": np.array(nodes), "top": np.array(top), "bottom": np.array(bottom),
            "slack": np.array(slack), "dt_s": h, "wall_s": float(min(walls))}


# --- MoorDyn's side --------------------------------------------------------------------------


def _moordyn_schedule(path: np.ndarray, h: float, nsteps: int) -> tuple:
    """Per MoorDyn step k: top position at t_k, the secant velocity over the step, and the
    secant rate of the unstretched length (our frame, t_k = k h)."""
    t = np.arange(nsteps + 1) * h
    s = np.array([path_displacement(path, tk)[0] for tk in t])
    L = np.array([path_length(path, tk)[0] for tk in t])
    d = path[K_DIR:K_DIR + 3]
    pos = path[K_TOP:K_TOP + 3] + s[:-1, None] * d
    vel = (np.diff(s) / h)[:, None] * d
    # rounded: the secant of a linear ramp carries rounding noise, and every change of the
    # rate costs a call of MoorDyn's setter
    return pos, vel, np.round(np.diff(L) / h, 9)


def _write_moordyn_inputs(setup: _Setup, h: float, workdir: str) -> float:
    """``lines.txt`` (coupled top point, RK4 at step h) and ``current_profile.txt`` in
    ``workdir``; returns the depth of the frame shift."""
    p = setup.md_params
    depth = float(setup.top[2]) - float(p.tether.anchor_position[2]) + SUBMERGENCE
    with open(os.path.join(workdir, "lines.txt"), "w") as f:
        f.write(moordyn_input(p, setup.top, depth, h, "RK4", top_attachment="Coupled",
                              mass_per_length=setup.md_mass))
    with open(os.path.join(workdir, "current_profile.txt"), "w") as f:
        f.write(current_profile(WIND, depth))
    return depth


def step_call_overhead(md, setup: _Setup, seconds: float = 20.0, repeats: int = 3) -> dict:
    """MoorDyn's wall time with the top end held for ``seconds``: one Step call per MoorDyn
    step (as the driven cases need) against one Step call per second (MoorDyn stepping
    internally); best of ``repeats``. Their ratio is the share of the Python call per step."""
    h = OUTPUT_DT / MOORDYN_SUBSTEPS
    walls = {"per_step_s": [], "per_second_s": []}
    with tempfile.TemporaryDirectory(prefix="aerostat_moordyn_dyn_") as tmp:
        depth = _write_moordyn_inputs(setup, h, tmp)
        top0 = (setup.top - np.array([0.0, 0.0, depth])).tolist()
        for _ in range(repeats):
            for key, chunk in (("per_step_s", h), ("per_second_s", 1.0)):
                with _captured_c_output(os.path.join(tmp, "console.txt")):
                    system = md.Create(os.path.join(tmp, "lines.txt"))
                    try:
                        md.Init(system, top0, [0.0, 0.0, 0.0])
                        t, n = 0.0, round(seconds / chunk)
                        t0 = time.perf_counter()
                        for _k in range(n):
                            md.Step(system, top0, [0.0, 0.0, 0.0], t, chunk)
                            t += chunk
                        walls[key].append(time.perf_counter() - t0)
                    finally:
                        md.Close(system)
    out = {k: float(min(v)) for k, v in walls.items()}
    out["ratio"] = out["per_step_s"] / out["per_second_s"]
    out["simulated_s"] = seconds
    return out


def _run_moordyn(md, setup: _Setup, path: np.ndarray, case: DrivenCase, substeps: int,
                 workdir: str, record: bool) -> dict:
    """One MoorDyn run: settle with the top end held, then the drive; sampled every OUTPUT_DT
    when ``record`` (else timed: the Step loop of the drive only)."""
    h = OUTPUT_DT / substeps
    shift = np.array([0.0, 0.0, _write_moordyn_inputs(setup, h, workdir)])
    n_out = round(case.duration / OUTPUT_DT)
    nsteps = n_out * substeps
    pos, vel, Ld = _moordyn_schedule(path, h, nsteps)
    pos = (pos - shift).tolist()
    vel = vel.tolist()
    top0 = (setup.top - shift).tolist()
    log = os.path.join(workdir, "console.txt")
    out = {"nodes": [], "top": [], "bottom": [], "slack": [], "dt_s": h}
    try:
        with _captured_c_output(log):
            system = md.Create(os.path.join(workdir, "lines.txt"))
            try:
                if md.Init(system, top0, [0.0, 0.0, 0.0]) != 0:
                    raise RuntimeError("MoorDyn initialization failed:\n" + _tail(log))
                line = md.GetLine(system, 1)
                N = md.GetLineN(line)
                t = -setup.settle
                for _ in range(round(setup.settle / h)):
                    md.Step(system, top0, [0.0, 0.0, 0.0], t, h)
                    t += h
                if record:
                    _sample_moordyn(md, line, N, shift, out)
                rate = 0.0
                t0 = time.perf_counter()
                for k in range(nsteps):
                    if Ld[k] != rate:
                        rate = float(Ld[k])
                        _set_length_rate(md, line, rate)
                    md.Step(system, pos[k], vel[k], t, h)
                    t += h
                    if record and (k + 1) % substeps == 0:
                        _sample_moordyn(md, line, N, shift, out)
                out["wall_s"] = time.perf_counter() - t0
            finally:
                md.Close(system)
    except RuntimeError as exc:
        raise RuntimeError(f"MoorDyn run of {case.name!r} failed (RK4, dt = {h:.3g} s): {exc}\n"
                           + _tail(log)) from exc
    for key in ("nodes", "top", "bottom", "slack"):
        out[key] = np.array(out[key])
    return out


def _set_length_rate(md, line, rate: float) -> None:
    """``SetLineUnstretchedLengthVel``. The 2.7.2 binding returns None without a new reference
    (measured: ``sys.getrefcount(None)`` falls by one per call, and the interpreter aborts at
    exit with "Fatal Python error: none_dealloc"), so the reference it takes is given back, for
    good (a reference held in a list would be released at exit and abort just the same)."""
    md.SetLineUnstretchedLengthVel(line, rate)
    ctypes.pythonapi.Py_IncRef(ctypes.py_object(None))


def _sample_moordyn(md, line, N: int, shift: np.ndarray, out: dict) -> None:
    """Append MoorDyn's node positions (our frame and order, top first), end tensions (the
    definitions of :func:`aerostat_gym.bench.moordyn._run_moordyn`) and slack segment count."""
    nodes = np.array([md.GetLineNodePos(line, i) for i in range(N, -1, -1)]) + shift
    out["nodes"].append(nodes)
    out["top"].append(float(np.linalg.norm(md.GetLineNodeForce(line, N))))
    f0 = np.asarray(md.GetLineNodeForce(line, 0)) - np.asarray(md.GetLineNodeDrag(line, 0))
    out["bottom"].append(float(np.linalg.norm(f0)))
    out["slack"].append(_segment_slack(nodes, md.GetLineUnstretchedLength(line)))


# --- comparison ------------------------------------------------------------------------------


def harmonic_fit(signal: np.ndarray, t: np.ndarray, omega: float) -> np.ndarray:
    """Amplitudes and phases [rad] of the first two harmonics: least-squares fit of
    a + sum_k R_k sin(k omega t + phase_k), k = 1, 2, to ``signal``; rows (R_k, phase_k).

    Both are fitted because a symmetric motion (across the wind) changes the tension at twice
    the drive frequency."""
    cols = [np.ones_like(t)]
    for k in (1, 2):
        cols += [np.sin(k * omega * t), np.cos(k * omega * t)]
    c = np.linalg.lstsq(np.column_stack(cols), signal, rcond=None)[0]
    return np.array([[math.hypot(c[2 * k - 1], c[2 * k]), math.atan2(c[2 * k], c[2 * k - 1])]
                     for k in (1, 2)])


def harmonic_lag(ours: np.ndarray, ref: np.ndarray, t: np.ndarray, period: float) -> dict:
    """Phase lag of ``ours`` behind ``ref`` in the harmonic (1 or 2, at the drive period) that
    dominates ``ref``: degrees of that harmonic's cycle and seconds (positive: ours lags)."""
    w = 2.0 * math.pi / period
    fa, fb = harmonic_fit(ours, t, w), harmonic_fit(ref, t, w)
    k = int(np.argmax(fb[:, 0]))
    lag = math.degrees((fb[k, 1] - fa[k, 1] + math.pi) % (2.0 * math.pi) - math.pi)
    return {"harmonic": k + 1, "lag_deg": lag, "lag_s": lag / 360.0 * period / (k + 1),
            "amplitude_ratio": float(fa[k, 0] / fb[k, 0]) if fb[k, 0] > 0 else float("nan")}


def correlation_lag(ours: np.ndarray, ref: np.ndarray, dt: float, max_lag: float = 2.0) -> float:
    """Delay [s] of ``ours`` behind ``ref`` at the peak of their cross-correlation (demeaned),
    refined by a parabola through the peak and its neighbours."""
    a, b = ours - ours.mean(), ref - ref.mean()
    kmax = int(round(max_lag / dt))
    lags = np.arange(-kmax, kmax + 1)
    cc = np.array([np.dot(a[max(k, 0):len(a) + min(k, 0)], b[max(-k, 0):len(b) - max(k, 0)])
                   for k in lags])
    i = int(np.argmax(cc))
    frac = 0.0
    if 0 < i < len(cc) - 1:
        den = cc[i - 1] - 2.0 * cc[i] + cc[i + 1]
        frac = 0.5 * (cc[i - 1] - cc[i + 1]) / den if den != 0 else 0.0
    return float((lags[i] + frac) * dt)


def compare_runs(ours: dict, ref: dict, case: DrivenCase, length: float) -> dict:
    """Figures of ``ours`` against ``ref`` over the case's window (module docstring)."""
    t = np.arange(len(ref["top"])) * OUTPUT_DT
    win = t >= case.window_start - 1e-9
    d = np.linalg.norm(ours["nodes"][win, 1:-1] - ref["nodes"][win, 1:-1], axis=2)
    out = {"pos_rms_pct": float(100.0 * np.sqrt(np.mean(d**2)) / length),
           "pos_max_pct": float(100.0 * d.max() / length)}
    for end in ("top", "bottom"):
        a, b = ours[end][win], ref[end][win]
        out[f"{end}_rms_pct"] = float(100.0 * np.sqrt(np.mean((a - b) ** 2)) / b.mean())
        if case.kind == SINE:
            h = harmonic_lag(a, b, t[win], case.period)
            out.update({f"{end}_{k}": v for k, v in h.items()})
        else:
            out[f"{end}_lag_s"] = correlation_lag(a, b, OUTPUT_DT)
    return out


def _slack_summary(run: dict, case: DrivenCase) -> dict:
    """When segments were slack (drive start to window end) and the tension extremes."""
    t = np.arange(len(run["top"])) * OUTPUT_DT
    s = run["slack"]
    on = np.nonzero(s > 0)[0]
    return {"max_slack_segments": int(s.max()),
            "slack_time_s": float(np.count_nonzero(s) * OUTPUT_DT),
            "first_slack_s": float(t[on[0]]) if on.size else None,
            "last_slack_s": float(t[on[-1]]) if on.size else None,
            "top_max_N": float(run["top"].max()), "top_min_N": float(run["top"].min()),
            "bottom_max_N": float(run["bottom"].max()),
            "bottom_min_N": float(run["bottom"].min())}


def run_case(case: DrivenCase, setup: _Setup | None = None, repeats: int = 3,
             step_check: bool = True, md=None) -> dict:
    """Run one case in both codes and compare.

    Parameters
    ----------
    case : DrivenCase
        The prescribed motion.
    setup : _Setup, optional
        From :func:`prepare` (default: the baseline variant).
    repeats : int
        Timed repeats of each code (the best is kept).
    step_check : bool
        Also run MoorDyn at half its step and report its difference from the reference.
    md : module, optional
        The ``moordyn`` module (imported when None).

    Returns
    -------
    dict with ``rk4`` and ``semi-implicit`` (:func:`compare_runs` figures plus ``wall_s``,
    ``dt_s`` and ``speed_ratio`` = MoorDyn wall / ours; the semi-implicit entry also has
    ``vs_our_rk4``, its figures against our RK4), ``moordyn`` (``wall_s``, ``dt_s``),
    ``moordyn_step_check`` (MoorDyn at half its step against the reference), ``slack`` (per code,
    :func:`_slack_summary`), ``is_slack`` (any segment slack in the window, either code),
    ``mean_top_tension_N``, ``within_targets`` (RK4 against the issue's bounds) and ``case``.
    """
    if repeats < 1:
        raise DynamicBenchError(f"repeats must be >= 1, got {repeats!r}")
    md = md or _import_moordyn()
    setup = setup or prepare()
    p = setup.params
    path = case.pack(setup.top, setup.lever, p.tether.length)
    L = p.tether.length
    with tempfile.TemporaryDirectory(prefix="aerostat_moordyn_dyn_") as tmp:
        ref = _run_moordyn(md, setup, path, case, MOORDYN_SUBSTEPS, tmp, record=True)
        walls = [_run_moordyn(md, setup, path, case, MOORDYN_SUBSTEPS, tmp, record=False)["wall_s"]
                 for _ in range(repeats)]
        fine = (_run_moordyn(md, setup, path, case, 2 * MOORDYN_SUBSTEPS, tmp, record=True)
                if step_check else None)
    md_wall = float(min(walls))
    res = {"case": case.name, "duration_s": case.duration, "window_start_s": case.window_start,
           "moordyn": {"dt_s": ref["dt_s"], "wall_s": md_wall,
                       "real_time_factor": case.duration / md_wall}}
    if fine is not None:
        res["moordyn_step_check"] = compare_runs(fine, ref, case, L)
    win = np.arange(len(ref["top"])) * OUTPUT_DT >= case.window_start - 1e-9
    res["mean_top_tension_N"] = float(ref["top"][win].mean())
    slack = {"moordyn": _slack_summary(ref, case)}
    runs = {}
    for integ in ("rk4", "semi-implicit"):
        ours = runs[integ] = _run_ours(setup, path, case, integ, repeats)
        fig = compare_runs(ours, ref, case, L)
        fig.update(dt_s=ours["dt_s"], wall_s=ours["wall_s"],
                   real_time_factor=case.duration / ours["wall_s"],
                   speed_ratio=md_wall / ours["wall_s"])
        res[integ] = fig
        slack[integ] = _slack_summary(ours, case)
    # the semi-implicit scheme against our RK4: its own time-step error, for comparison
    res["semi-implicit"]["vs_our_rk4"] = compare_runs(runs["semi-implicit"], runs["rk4"], case, L)
    res["slack"] = slack
    res["is_slack"] = bool(any(v["max_slack_segments"] > 0 for v in slack.values()))
    r = res["rk4"]
    res["within_targets"] = bool(r["pos_max_pct"] < POSITION_TARGET_PCT
                                 and r["top_rms_pct"] < TENSION_TARGET_PCT
                                 and r["bottom_rms_pct"] < TENSION_TARGET_PCT)
    return res


EXPLAIN_VARIANTS = ("crossflow_drag", "moordyn_drag", "no_buoyancy", "moordyn_slack_rule",
                    "moordyn_drag_and_slack_rule")


def _select_cases(base: Params, quick: bool, cases: list[str] | None) -> list[DrivenCase]:
    """The cases to run: the smoke case, the named ones, or the whole table."""
    table = standard_cases(base)
    if quick:
        harm = next(c for c in table if c.name == "across-harmonic-1m")
        return [DrivenCase(harm.name, SINE, harm.direction, harm.amplitude, harm.period,
                           window=10.0)]
    if cases is None:
        return table
    known = {c.name: c for c in table}
    missing = [c for c in cases if c not in known]
    if missing:
        raise DynamicBenchError(f"unknown case(s) {missing}; choose from {sorted(known)}")
    return [known[c] for c in cases]


def _outside_targets(row: dict) -> bool:
    """A case whose RK4 figures exceed the issue's bounds (slack or not)."""
    r = row["rk4"]
    return (r["pos_max_pct"] >= POSITION_TARGET_PCT
            or max(r["top_rms_pct"], r["bottom_rms_pct"]) >= TENSION_TARGET_PCT)


def run_dynamic_comparison(quick: bool = False, cases: list[str] | None = None,
                           variants: tuple = ("baseline",), repeats: int = 3,
                           explain: bool = True) -> dict:
    """The dynamic comparison table, and the switches applied to the cases outside the bounds.

    Parameters
    ----------
    quick : bool
        One short case (across the wind at the tether harmonic, 1 m, 10 s window, 15 s settle,
        no step check, one timed repeat): the smoke run.
    cases : list of str, optional
        Names from :func:`standard_cases` (default all).
    variants : tuple of str
        Which ``VARIANTS`` to run every selected case under.
    repeats : int
        Timed repeats per code and case (the best is kept).
    explain : bool
        Also run each case whose RK4 figures exceed the bounds (in the first variant) under
        ``EXPLAIN_VARIANTS`` (one repeat, no step check): the named differences switched off.

    Returns
    -------
    dict with ``rows`` (per variant, per case: :func:`run_case`), ``explained`` (per switch,
    per case outside the bounds: :func:`run_case`), ``settings`` (text), ``moordyn_version``,
    ``moordyn_step_call_overhead`` (:func:`step_call_overhead`) and the targets.
    """
    if repeats < 1:
        raise DynamicBenchError(f"repeats must be >= 1, got {repeats!r}")
    md = _import_moordyn()
    base = load_params(overrides={"environment.rho_air": RHO_AIR})
    table = _select_cases(base, quick, cases)
    settle = 15.0 if quick else SETTLE
    rows, overhead = {}, None
    for variant in variants:
        setup = prepare(variant, settle=settle)
        if overhead is None:
            overhead = step_call_overhead(md, setup, seconds=5.0 if quick else 20.0,
                                          repeats=1 if quick else repeats)
        rows[variant] = {c.name: run_case(c, setup, repeats=1 if quick else repeats,
                                          step_check=not quick, md=md) for c in table}
    explained = {}
    first = rows[variants[0]]
    over = [c for c in table if _outside_targets(first[c.name])] if explain else []
    for variant in EXPLAIN_VARIANTS if over else ():
        setup = prepare(variant, settle=settle)
        explained[variant] = {c.name: run_case(c, setup, repeats=1, step_check=False, md=md)
                              for c in over}
    return {"rows": rows, "explained": explained, "moordyn_version": _version(),
            "moordyn_step_call_overhead": overhead,
            "targets": {"position_max_pct_L": POSITION_TARGET_PCT,
                        "tension_rms_pct": TENSION_TARGET_PCT},
            "settings": _settings(base)}


def _settings(p: Params) -> str:
    return (f"MoorDyn {_version()} RK4 at dt = {OUTPUT_DT / MOORDYN_SUBSTEPS * 1e3:.3g} ms "
            f"(checked against {OUTPUT_DT / MOORDYN_SUBSTEPS / 2 * 1e3:.3g} ms), coupled top point "
            f"driven every step; ours RK4 at {OUTPUT_DT / RK4_SUBSTEPS * 1e3:.3g} ms and "
            f"semi-implicit at {p.simulation.semi_implicit_dt * 1e3:.3g} ms; n = "
            f"{p.tether.n_elements}, L = {p.tether.length} m, rho = {RHO_AIR}, uniform current "
            f"{WIND} m/s along +X, Cd = {p.tether.Cd_normal}, CdAx = {axial_cdt(p):.4g}, "
            f"BA = b = {p.derived.damping_b:.4g} N s; settle {SETTLE:.0f} s at the trim; samples "
            f"every {OUTPUT_DT} s; window {WINDOW:.0f} s after the first cycle (sines) or from "
            "the start (reel, drop)")


def format_table(rows: dict) -> str:
    """Markdown table of :func:`run_case` results, ``rows[variant][case]``."""
    head = ("| variant | case | slack | RK4 pos RMS / max (% L) | RK4 top / bottom T RMS (%) "
            "| RK4 top / bottom lag | SI pos RMS / max (% L) | SI top / bottom T RMS (%) "
            "| MoorDyn dt/2 check: pos max (% L) / top T (%) | speed ratio RK4 / SI |")
    lines = [head, "|" + "---|" * 10]
    for variant, by_case in rows.items():
        for name, r in by_case.items():
            a, b = r["rk4"], r["semi-implicit"]
            lag = (f"{a['top_lag_deg']:+.2f} / {a['bottom_lag_deg']:+.2f} deg (h{a['top_harmonic']})"
                   if "top_lag_deg" in a
                   else f"{a['top_lag_s'] * 1e3:+.1f} / {a['bottom_lag_s'] * 1e3:+.1f} ms")
            chk = r.get("moordyn_step_check")
            chk_s = f"{chk['pos_max_pct']:.4f} / {chk['top_rms_pct']:.3f}" if chk else "-"
            lines.append(
                f"| {variant} | {name} | {'yes' if r['is_slack'] else 'no'} "
                f"| {a['pos_rms_pct']:.4f} / {a['pos_max_pct']:.4f} "
                f"| {a['top_rms_pct']:.3f} / {a['bottom_rms_pct']:.3f} | {lag} "
                f"| {b['pos_rms_pct']:.4f} / {b['pos_max_pct']:.4f} "
                f"| {b['top_rms_pct']:.3f} / {b['bottom_rms_pct']:.3f} | {chk_s} "
                f"| {a['speed_ratio']:.1f} / {b['speed_ratio']:.1f} |")
    return "\n".join(lines)


def format_report(res: dict) -> str:
    """Text report of :func:`run_dynamic_comparison`: settings, table, switches, overhead."""
    o = res["moordyn_step_call_overhead"]
    out = [f"Dynamic comparison with MoorDyn {res['moordyn_version']}: {res['settings']}", "",
           format_table(res["rows"])]
    if res["explained"]:
        out += ["", "Cases outside the bounds with each named difference switched off "
                "(one repeat, no step check; semi-implicit columns are the unswitched scheme "
                "except for the MoorDyn-side switches):", "", format_table(res["explained"])]
    out += ["", f"MoorDyn, top end held {o['simulated_s']:g} s: one Step call per step "
            f"{o['per_step_s']:.3f} s, one per second {o['per_second_s']:.3f} s "
            f"(ratio {o['ratio']:.2f})"]
    return "\n".join(out)
