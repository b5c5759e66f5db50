"""The wind interface of the compiled core: air velocity at any point and time.

Every aerodynamic force in the model (each tether element, the hull, each fin) reads the air
velocity at its own point through :func:`air_velocity`, so turbulence and gusts plug in here
without touching the physics.

``air_velocity(x, y, z, t, wp, wf) -> (wx, wy, wz)`` (inertial components, m/s) where

- ``wp`` is a flat float64 wind-parameter vector indexed by the ``W_*`` constants below;
- ``wf`` is a float64 array of shape (n_heights, n_times, 3) holding a turbulence field
  (u along the mean wind, v lateral, w vertical) on a uniform height grid and time grid;
  an array with n_times == 0 means no turbulence.

Mean profiles (height z above the anchor, clipped below at ``W_ZMIN``):
uniform U(z) = U_ref; power U(z) = U_ref (z / z_ref)^alpha; log U(z) = U_ref ln(z/z0) / ln(z_ref/z0).
The wind blows toward the heading ``direction`` (from +X toward +Y). Mean-wind axes: u along
that heading, v to its left (+Y for direction 0), w up.

Frozen turbulence (Taylor). The field ``wf[k, j]`` is the fluctuation seen at height z_k at time
t_j by a point at the anchor's along-wind station (x_a = 0). The whole field is advected
downwind at one speed U_a = ``wp[W_TAYLOR_U]`` (the mean speed at the aerostat's nominal height,
see :func:`aerostat_gym.wind.build_wind`), so a point at along-wind coordinate x_a reads
``wf`` at the delayed time t - x_a / U_a: an 18 m hull meets a gust at the nose first and at
the fins about 18 / U_a seconds later. The 1 - cos gust is frozen in the same flow and moves at
the same U_a. The field is sampled by bilinear interpolation in height and time, so the
integrator's substeps see a continuous wind.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

# --- wind parameter vector layout ----------------------------------------------------------------
W_PROFILE = 0  # 0 uniform, 1 power law, 2 log law
W_UREF = 1  # mean speed at the reference height [m/s]
W_ZREF = 2  # reference height [m]
W_ALPHA = 3  # power-law exponent [-]
W_Z0 = 4  # roughness length [m]
W_DIRC = 5  # cos(direction)
W_DIRS = 6  # sin(direction)
W_ZMIN = 7  # heights below this are clipped for the profile [m]
# discrete 1 - cos gust (added along the mean-wind axes): amplitude u, v, w, length scale, onset
W_GUST_ON = 8
W_GUST_AU = 9  # peak gust along the mean wind [m/s]
W_GUST_AV = 10  # peak lateral gust [m/s]
W_GUST_AW = 11  # peak vertical gust [m/s]
W_GUST_LEN = 12  # gust length along the wind [m] (duration at a fixed point = length / U_a)
W_GUST_X0 = 13  # gust front position along the wind at t = 0, relative to the anchor [m]
# turbulence field on a grid: heights z_k = FIELD_Z0 + k FIELD_DZ, times t_j = FIELD_T0 + j FIELD_DT
W_TURB_ON = 14
W_FIELD_Z0 = 15  # height of the first field row [m]
W_FIELD_DZ = 16  # height step of the field rows [m]
W_FIELD_T0 = 17  # time of the first field sample [s] (negative: room for the Taylor delay)
W_FIELD_DT = 18  # time step of the field [s]
W_TAYLOR_U = 19  # advection speed U_a of the frozen field and of the gust [m/s]
W_FIELD_XDOWN = 20  # the field covers points up to this far downwind of the anchor [m]
W_FIELD_XUP = 21  # ... and up to this far upwind of the anchor [m]
# derived slots, kept in step by set_advection / set_field (multiplications are cheaper than
# divisions in the sampler): 1/dz [1/m], 1/dt [1/s], 1/(U_a dt) [1/m]
W_FIELD_IDZ = 22
W_FIELD_IDT = 23
W_TAYLOR_IDX = 24
# per-episode scale of the field's u, v, w (1 for a field generated at its own sigmas; the
# environment reads a bank of unit-variance fields and puts each episode's sigmas here)
W_FIELD_SU = 25
W_FIELD_SV = 26
W_FIELD_SW = 27
# 1: the field is periodic in time with its own length (an inverse-FFT synthesis is), and is
# read modulo that length, so an episode of any length is served; 0: edge values are held
W_FIELD_PERIODIC = 28
# 1 - the correlation of adjacent height rows of the field's u, v, w (0: no correction). Linear
# interpolation between rows whose correlation is rho has variance 1 - 2 a (1 - a) (1 - rho) at
# the fraction a of the way from one to the next (rho 0.67-0.9 for the IEC coherence of 5 m
# rows: 0.83-0.95 of the rows' variance midway); the sampler divides by its square root, so a
# point between rows has the rows' sigma (set_row_decorrelation)
W_FIELD_DU = 29
W_FIELD_DV = 30
W_FIELD_DW = 31
W_SIZE = 32

PROFILES = {"uniform": 0, "power": 1, "log": 2}
MIN_ADVECTION_SPEED = 1.0  # floor of U_a [m/s]: Taylor's hypothesis fails in calm air anyway


def pack_wind(profile: str = "uniform", speed: float = 0.0, direction_deg: float = 0.0,
              reference_height: float = 10.0, shear_exponent: float = 0.14,
              roughness_length: float = 0.05) -> np.ndarray:
    """Wind-parameter vector for a steady mean wind (no gust, no turbulence).

    The advection speed ``W_TAYLOR_U`` is set to max(speed, MIN_ADVECTION_SPEED); :func:`set_advection`
    or :func:`aerostat_gym.wind.build_wind` replace it with the speed at the aerostat height.
    """
    if profile not in PROFILES:
        raise ValueError(f"unknown wind profile {profile!r}; choose one of {sorted(PROFILES)}")
    if not (math.isfinite(speed) and speed >= 0):
        raise ValueError(f"wind speed must be finite and >= 0, got {speed!r}")
    if profile == "log" and not roughness_length < reference_height:
        raise ValueError(f"the log profile needs a roughness length ({roughness_length:g} m) "
                         f"below its reference height ({reference_height:g} m)")
    wp = np.zeros(W_SIZE)
    wp[W_PROFILE] = PROFILES[profile]
    wp[W_UREF] = speed
    wp[W_ZREF] = reference_height
    wp[W_ALPHA] = shear_exponent
    wp[W_Z0] = roughness_length
    a = math.radians(direction_deg)
    wp[W_DIRC], wp[W_DIRS] = math.cos(a), math.sin(a)
    wp[W_ZMIN] = max(roughness_length * 1.01, 0.5)
    wp[W_TAYLOR_U] = max(speed, MIN_ADVECTION_SPEED)
    wp[W_FIELD_SU] = wp[W_FIELD_SV] = wp[W_FIELD_SW] = 1.0
    return wp


def set_field_scale(wp: np.ndarray, sigmas) -> None:
    """Scale the field's u, v, w by ``sigmas`` (in place): a unit-variance field then has these
    standard deviations [m/s]."""
    su, sv, sw = (float(s) for s in sigmas)
    if not all(math.isfinite(s) and s >= 0 for s in (su, sv, sw)):
        raise ValueError(f"field scales must be finite and >= 0, got {sigmas!r}")
    wp[W_FIELD_SU], wp[W_FIELD_SV], wp[W_FIELD_SW] = su, sv, sw


def mean_wind(wind, speed: float | None = None) -> np.ndarray:
    """Wind-parameter vector of the mean profile configured in a
    :class:`aerostat_gym.params.WindParams`, at reference speed ``speed`` [m/s] (default: the
    configured ``wind.speed``). The one place a configuration becomes a packed mean wind."""
    return pack_wind(wind.profile, wind.speed if speed is None else speed, wind.direction_deg,
                     wind.reference_height, wind.shear_exponent, wind.roughness_length)


def set_advection(wp: np.ndarray, height: float, floor: float = MIN_ADVECTION_SPEED) -> float:
    """Set the frozen-flow advection speed U_a = max(U(height), floor) in place; return it."""
    ua = max(float(mean_speed(float(height), wp)), floor)
    wp[W_TAYLOR_U] = ua
    _update_derived(wp)
    return ua


def _update_derived(wp: np.ndarray) -> None:
    """Recompute the derived slots from dz, dt and U_a (left 0 while there is no field)."""
    if wp[W_FIELD_DZ] > 0 and wp[W_FIELD_DT] > 0:
        wp[W_FIELD_IDZ] = 1.0 / wp[W_FIELD_DZ]
        wp[W_FIELD_IDT] = 1.0 / wp[W_FIELD_DT]
        wp[W_TAYLOR_IDX] = wp[W_FIELD_IDT] / wp[W_TAYLOR_U]


def derived_consistent(wp: np.ndarray) -> bool:
    """True when the derived slots match dz, dt and U_a (always true without a field)."""
    if wp[W_TURB_ON] == 0.0:
        return True
    want = np.array([1.0 / wp[W_FIELD_DZ], 1.0 / wp[W_FIELD_DT],
                     1.0 / (wp[W_FIELD_DT] * wp[W_TAYLOR_U])])
    return bool(np.allclose(wp[[W_FIELD_IDZ, W_FIELD_IDT, W_TAYLOR_IDX]], want, rtol=1e-12))


def set_gust(wp: np.ndarray, amplitude: tuple[float, float, float], length: float,
             onset: float, position: float = 0.0) -> None:
    """Add a discrete 1 - cos gust to ``wp`` in place.

    Parameters
    ----------
    wp : ndarray
        Wind-parameter vector; its advection speed U_a = ``wp[W_TAYLOR_U]`` must be set first.
    amplitude : (float, float, float)
        Peak gust (u along the mean wind, v lateral, w vertical) [m/s].
    length : float
        Gust length along the wind [m] (> 0); a fixed point sees it for length / U_a seconds.
    onset : float
        Time at which the gust front reaches the along-wind station ``position`` [s].
    position : float
        Along-wind coordinate of that station, relative to the anchor [m].

    Notes
    -----
    The gust is frozen in the mean flow: with xi = U_a (t - onset) - (x_a - position),
    g = A (1 - cos(2 pi xi / length)) / 2 for 0 < xi < length, else 0. A point at x_a sees the
    peak A at t = onset + (x_a - position) / U_a + length / (2 U_a).
    """
    if not (math.isfinite(length) and length > 0):
        raise ValueError(f"gust length must be finite and > 0 [m], got {length!r}")
    if not all(math.isfinite(a) for a in amplitude) or not math.isfinite(onset):
        raise ValueError(f"gust amplitude and onset must be finite, got {amplitude!r}, {onset!r}")
    wp[W_GUST_ON] = 1.0
    wp[W_GUST_AU], wp[W_GUST_AV], wp[W_GUST_AW] = amplitude
    wp[W_GUST_LEN] = length
    wp[W_GUST_X0] = position - wp[W_TAYLOR_U] * onset


def set_field(wp: np.ndarray, z0: float, dz: float, t0: float, dt: float,
              x_down: float, x_up: float) -> None:
    """Switch the turbulence field on in ``wp`` (in place) and record its grids and coverage."""
    wp[W_TURB_ON] = 1.0
    wp[W_FIELD_Z0], wp[W_FIELD_DZ] = z0, dz
    wp[W_FIELD_T0], wp[W_FIELD_DT] = t0, dt
    wp[W_FIELD_XDOWN], wp[W_FIELD_XUP] = x_down, x_up
    if not (dz > 0 and dt > 0 and wp[W_TAYLOR_U] > 0):
        raise ValueError(f"field steps and advection speed must be > 0, got dz={dz!r}, dt={dt!r}, "
                         f"U_a={wp[W_TAYLOR_U]!r}")
    _update_derived(wp)


def set_row_decorrelation(wp: np.ndarray, decorrelation) -> None:
    """Record 1 - rho of adjacent field rows for u, v, w in ``wp`` (in place; see
    :data:`W_FIELD_DU`): the sampler then keeps the rows' variance between them."""
    d = tuple(float(v) for v in decorrelation)
    if len(d) != 3 or not all(math.isfinite(v) and 0.0 <= v < 2.0 for v in d):
        raise ValueError(f"row decorrelation must be three values 1 - rho in [0, 2), got "
                         f"{decorrelation!r}")
    wp[W_FIELD_DU], wp[W_FIELD_DV], wp[W_FIELD_DW] = d


def set_periodic(wp: np.ndarray, periodic: bool = True) -> None:
    """Read the field modulo its length (in place): for fields synthesised by an inverse FFT,
    which are exactly periodic, so the wrap is seamless (sample n equals sample 0)."""
    wp[W_FIELD_PERIODIC] = 1.0 if periodic else 0.0


NO_FIELD = np.zeros((1, 0, 3))

# Compilation flags of the wind kernels. They only read arrays they are given, so they need no
# reference counting: _nrt=False drops the atomic incref/decref pairs that numba otherwise emits
# around array arguments used inside branches (measured: 29 -> 6 ns per call without a field,
# 35 -> 13 ns with one). error_model="numpy" drops the zero-division checks (whose exception
# paths also block those optimisations); U_a, dz and dt are positive by construction.
# Do not give air_velocity inline="always": numba-IR inlining would put it back under the
# caller's reference counting.
_JIT = {"cache": True, "error_model": "numpy", "_nrt": False}


@njit(**_JIT, inline="always")
def mean_speed(z, wp):
    """Mean wind speed at height z [m/s]."""
    prof = wp[W_PROFILE]
    if prof == 0.0:
        return wp[W_UREF]
    zz = max(z, wp[W_ZMIN])
    if prof == 1.0:
        return wp[W_UREF] * (zz / wp[W_ZREF]) ** wp[W_ALPHA]
    return wp[W_UREF] * math.log(zz / wp[W_Z0]) / math.log(wp[W_ZREF] / wp[W_Z0])


@njit(**_JIT, inline="always")
def _grid_index(f, n):
    """Lower grid index and weight of fractional position f on a grid of n points (clamped).

    Written so that a NaN position (a state gone non-finite) reads the first grid point rather
    than stray memory: the sampler runs without bounds checks.
    """
    if f > 0.0:
        f = min(f, n - 1.0)
    else:
        f = 0.0
    k = min(int(f), max(n - 2, 0))
    return k, f - k


@njit(**_JIT, inline="always")
def _periodic_index(f, n):
    """Lower index, weight and upper index of fractional position f on a periodic grid of n
    points (f taken modulo n; a NaN or infinite position reads the first point)."""
    if not abs(f) < 1e300:
        f = 0.0
    f = f - n * math.floor(f / n)
    k = min(int(f), n - 1)
    k1 = k + 1 if k + 1 < n else 0
    return k, f - k, k1


@njit(**_JIT, inline="always")
def _field_sample(xa, z, t, wp, wf):
    """Bilinear interpolation of the field at height z and Taylor-delayed time t - xa / U_a,
    rescaled in height to the rows' variance (:data:`W_FIELD_DU`).

    Outside the height grid the nearest edge value is held (heights above the top row read the
    top row). In time, a periodic field (``W_FIELD_PERIODIC``) is read modulo its length;
    otherwise the edge is held and :func:`aerostat_gym.wind.check_covers` verifies that a run
    stays inside.
    """
    nz, nt = wf.shape[0], wf.shape[1]
    kz, az = _grid_index((z - wp[W_FIELD_Z0]) * wp[W_FIELD_IDZ], nz)
    # field time index of t - xa / U_a: ((t - t0) / dt) - xa / (U_a dt)
    ft = (t - wp[W_FIELD_T0]) * wp[W_FIELD_IDT] - xa * wp[W_TAYLOR_IDX]
    if wp[W_FIELD_PERIODIC] != 0.0:
        kt, at, kt1 = _periodic_index(ft, nt)
    else:
        kt, at = _grid_index(ft, nt)
        kt1 = kt + 1
    kz1 = kz + 1 if nz > 1 else kz
    w00 = (1.0 - az) * (1.0 - at)
    w01 = (1.0 - az) * at
    w10 = az * (1.0 - at)
    w11 = az * at
    # the interpolation's variance loss between partly correlated rows, restored (W_FIELD_DU)
    g = 2.0 * az * (1.0 - az)
    return ((w00 * wf[kz, kt, 0] + w01 * wf[kz, kt1, 0] + w10 * wf[kz1, kt, 0]
             + w11 * wf[kz1, kt1, 0]) / math.sqrt(1.0 - g * wp[W_FIELD_DU]),
            (w00 * wf[kz, kt, 1] + w01 * wf[kz, kt1, 1] + w10 * wf[kz1, kt, 1]
             + w11 * wf[kz1, kt1, 1]) / math.sqrt(1.0 - g * wp[W_FIELD_DV]),
            (w00 * wf[kz, kt, 2] + w01 * wf[kz, kt1, 2] + w10 * wf[kz1, kt, 2]
             + w11 * wf[kz1, kt1, 2]) / math.sqrt(1.0 - g * wp[W_FIELD_DW]))


@njit(**_JIT, inline="always")
def _gust(xa, t, wp):
    """1 - cos gust factor in [0, 1] at along-wind station xa and time t (frozen, moving at U_a)."""
    xi = wp[W_TAYLOR_U] * t - (xa - wp[W_GUST_X0])
    if 0.0 < xi < wp[W_GUST_LEN]:
        return 0.5 * (1.0 - math.cos(2.0 * math.pi * xi / wp[W_GUST_LEN]))
    return 0.0


@njit(**_JIT, inline="always")
def _air_velocity(x, y, z, t, wp, wf):
    """Body of :func:`air_velocity`, inlined into it and into :func:`air_velocity_batch`."""
    c, s = wp[W_DIRC], wp[W_DIRS]
    # along-wind coordinate of the point: sets the Taylor delay of the frozen field and gust
    xa = c * x + s * y
    ua = mean_speed(z, wp)
    va = 0.0
    wa = 0.0
    if wp[W_GUST_ON] != 0.0:
        g = _gust(xa, t, wp)
        ua += wp[W_GUST_AU] * g
        va += wp[W_GUST_AV] * g
        wa += wp[W_GUST_AW] * g
    if wp[W_TURB_ON] != 0.0 and wf.shape[1] > 1:
        du, dv, dw = _field_sample(xa, z, t, wp, wf)
        ua += wp[W_FIELD_SU] * du
        va += wp[W_FIELD_SV] * dv
        wa += wp[W_FIELD_SW] * dw
    # rotate mean-wind axes (u along the heading, v to its left) to inertial X, Y
    return c * ua - s * va, s * ua + c * va, wa


@njit(**_JIT, inline="always")
def _air_acceleration(x, y, z, t, wp, wf, length):
    """Body of :func:`air_acceleration`."""
    tau = length / wp[W_TAYLOR_U]
    if wp[W_TURB_ON] != 0.0 and wf.shape[1] > 1:
        tau = max(tau, wp[W_FIELD_DT])
    if tau <= 0.0:
        return 0.0, 0.0, 0.0
    h = 0.5 * tau
    u1, v1, w1 = _air_velocity(x, y, z, t + h, wp, wf)
    u0, v0, w0 = _air_velocity(x, y, z, t - h, wp, wf)
    it = 1.0 / tau
    return (u1 - u0) * it, (v1 - v0) * it, (w1 - w0) * it


@njit(**_JIT)
def air_acceleration(x, y, z, t, wp, wf, length):
    """Local time derivative dW/dt (inertial, m/s^2) of the air velocity at the fixed point
    (x, y, z) [m] and time t [s], averaged along the wind over ``length`` [m] (a hull's).

    Notes
    -----
    The difference [W(t + tau/2) - W(t - tau/2)] / tau with tau = length / U_a (at least one
    field time step) is exactly the time derivative of W averaged over the window tau, i.e. (by
    Taylor's frozen flow) of W averaged over ``length`` along the wind. A body feels the
    pressure gradient averaged over its volume, so eddies shorter than the hull add nothing;
    without the average the acceleration of a von Karman field grows without bound with the
    grid resolution (its spectrum f^2 S(f) ~ f^(1/3)). The steady mean wind cancels exactly; a
    field linear in time gives its slope exactly.

    This is the acceleration of the air past a point held in place (what a moored body sees).
    The frozen field advected at U_a has, by construction, no material acceleration
    DW/Dt = dW/dt + U_a dW/dx_a = 0; the local derivative is the one the air-inertia force
    uses, as in Morison's equation for a body held in a wave field.
    """
    return _air_acceleration(x, y, z, t, wp, wf, length)


def air_is_unsteady(wp: np.ndarray, wf: np.ndarray) -> bool:
    """True when the air can accelerate: a gust or a turbulence field is switched on."""
    return bool(wp[W_GUST_ON] != 0.0 or (wp[W_TURB_ON] != 0.0 and wf.shape[1] > 1))


@njit(**_JIT)
def air_velocity(x, y, z, t, wp, wf):
    """Air velocity (inertial, m/s) at point (x, y, z) [m] and time t [s]."""
    return _air_velocity(x, y, z, t, wp, wf)


@njit(**_JIT)
def air_velocity_batch(t, w, npts, base, wp, wf):
    """Air velocity at npts points in one call (saves a function call per point).

    Reads point i at ``w[base + 3 i : base + 3 i + 3]`` and writes its air velocity to
    ``w[base + 3 npts + 3 i : ... + 3]`` (the layout of the core's work array); same values as
    :func:`air_velocity`.
    """
    out = base + 3 * npts
    for i in range(npts):
        j = base + 3 * i
        ax, ay, az = _air_velocity(w[j], w[j + 1], w[j + 2], t, wp, wf)
        w[out + 3 * i] = ax
        w[out + 3 * i + 1] = ay
        w[out + 3 * i + 2] = az
