"""Modal (pendulum pole-placement) winch controller: the frontier reference of the winch baselines.

Design at one mean wind speed U (:func:`design_modal`), on the same linear model as the LQR
(:func:`aerostat_gym.agents.lqr.design_lqr`: trim, :func:`aerostat_gym.analysis.linear.linearize`
with the brake released and the speed loop holding v_set = 0, zero-order hold at the control
step dt), restricted to the longitudinal states and the winch (L, v_w): the lateral states are
uncontrollable from the winch (see :mod:`aerostat_gym.agents.lqr`).

Modal control with one input. Let w_i be the left eigenvectors of the continuous A (rows,
w_i A = lambda_i w_i); they are also the left eigenvectors of Ad = expm(A dt), with eigenvalues
z_i = exp(lambda_i dt), and they are orthogonal to every right eigenvector v_j, j != i. A gain
confined to the row span of a chosen set M of left eigenvectors, K = k^T T with
T = [Re w_p; Im w_p; w_L], leaves every other mode untouched, since K v_j = 0 gives
(Ad - Bd K) v_j = z_j v_j. Projected on T the loop is the 3-state problem
T (Ad - Bd K) = (Lambda - b k^T) T, with Lambda the real form of the moved eigenvalues and
b = T Bd, whose three poles Ackermann's formula places exactly. Two sets of poles are moved:

- the pendulum pair, to damping ratio ``zeta`` at the open-loop natural frequency times
  ``wn_factor`` (continuous s = -zeta w_n +- i w_n sqrt(1 - zeta^2), discrete z = exp(s dt));
- the paid-out length's neutral pole (with the brake released and v_set = 0 any length is an
  equilibrium: lambda = 0, z = 1) to exp(-dt / length_time): the slow length-restoring loop,
  which returns the tether to its trim length with time constant ``length_time`` (30 s).

Pitching, axial-spring and tether modes keep their open-loop (free winch) eigenvalues exactly,
which is what makes the design a clean frontier reference: the pendulum damping it buys is paid
for in reel speed only, with no trade against the other modes. The schedule
(:class:`ModalSchedule`) designs at each table speed and interpolates the gains linearly in U,
like :class:`aerostat_gym.agents.lqr.LQRSchedule`, whose lookup and policy it reuses.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import linear_sum_assignment

from ..analysis.trim import Equilibrium, find_equilibrium
from ..params import Params
from .lqr import (
    LQRDesign,
    LQRPolicy,
    LQRSchedule,
    design_lqr,
    discretize,
)

#: Time constant of the length-restoring loop [s] (the pole the winch's neutral length mode is
#: moved to, exp(-dt / 30) in z).
DEFAULT_LENGTH_TIME = 30.0
#: Default pendulum damping-ratio schedule: (wind speed [m/s], target zeta), linear in between
#: and held beyond the ends. Chosen so that a 10 m along-wind swing asks for a peak reel
#: set-point within the winch's 1 m/s (measured on the linear model, see :func:`peak_set_point`).
DEFAULT_ZETA_TABLE = ((2.0, 0.12), (5.0, 0.20), (10.0, 0.60), (15.0, 0.85), (16.0, 0.85))
#: Largest |z_closed - z_designed| accepted when the design checks its own placement.
PLACEMENT_TOL = 1e-6


class ModalDesignError(RuntimeError):
    """The moved modes are not controllable from the winch or the placement failed."""


def default_zeta(wind_speed: float) -> float:
    """Pendulum target damping ratio of :data:`DEFAULT_ZETA_TABLE` at ``wind_speed``."""
    u, z = np.array(DEFAULT_ZETA_TABLE).T
    return float(np.interp(wind_speed, u, z))


def _check_target(zeta: float, wn_factor: float, length_time: float) -> None:
    if not (isinstance(zeta, float | int) and 0.0 < zeta < 1.0):
        raise ValueError(f"zeta must lie in (0, 1) (an oscillatory pendulum pair), got {zeta!r}")
    if not (math.isfinite(wn_factor) and wn_factor > 0):
        raise ValueError(f"wn_factor must be finite and > 0, got {wn_factor!r}")
    if not (math.isfinite(length_time) and length_time > 0):
        raise ValueError(f"length_time must be finite and > 0 [s], got {length_time!r}")


def pendulum_target(wn: float, zeta: float, dt: float) -> complex:
    """Discrete pole exp(s dt) of the continuous pair s = -zeta wn + i wn sqrt(1 - zeta^2)."""
    return complex(np.exp(complex(-zeta * wn, wn * math.sqrt(1.0 - zeta * zeta)) * dt))


def left_eigenvector(A: np.ndarray, lam: complex) -> np.ndarray:
    """Row w with w A = lam w (unit norm): the null vector of (A - lam I)^T by SVD."""
    M = (A - lam * np.eye(A.shape[0])).T
    _, s, vh = np.linalg.svd(M)
    return vh[-1].conj()


def real_modal_block(lam_p: complex, lam_l: float) -> np.ndarray:
    """Lambda with T Ad = Lambda T for T = [Re w_p; Im w_p; w_L] (w_p Ad = lam_p w_p).

    With w_p = a + i b and lam_p = sigma + i omega: a Ad = sigma a - omega b and
    b Ad = omega a + sigma b.
    """
    s, w = lam_p.real, lam_p.imag
    return np.array([[s, -w, 0.0], [w, s, 0.0], [0.0, 0.0, lam_l]])


def ackermann(Lam: np.ndarray, b: np.ndarray, poles) -> np.ndarray:
    """k with eig(Lam - b k^T) = poles (single input): k^T = e_n^T C^-1 phi(Lam), C the
    controllability matrix [b, Lam b, ...] and phi the desired characteristic polynomial."""
    n = Lam.shape[0]
    C = np.column_stack([np.linalg.matrix_power(Lam, j) @ b for j in range(n)])
    coeffs = np.real(np.poly(poles))
    phi = sum(c * np.linalg.matrix_power(Lam, n - j) for j, c in enumerate(coeffs))
    e = np.zeros(n)
    e[-1] = 1.0
    return np.linalg.solve(C.T, e) @ phi


@dataclass
class ModalDesign:
    """One modal design at mean wind speed ``wind_speed``.

    Attributes
    ----------
    K : numpy.ndarray
        (6n+9,) gain over [x - x_trim; z], v_set = -K [dx; z] in m/s; the integral entry and the
        lateral entries are 0.
    x_trim : numpy.ndarray
        Trim state (6n+8).
    wind_speed : float
        U [m/s].
    dt : float
        Control step [s].
    zeta : float
        Designed pendulum damping ratio.
    wn : float
        Designed pendulum natural frequency [rad/s].
    length_time : float
        Time constant of the length loop [s].
    index : numpy.ndarray
        Full-layout indices of the designed subset (longitudinal, then L, v_w).
    Ad : numpy.ndarray
        Discrete open-loop matrix of the subset.
    Bd : numpy.ndarray
        Discrete input column of the subset.
    open_poles : numpy.ndarray
        Discrete open-loop eigenvalues of the subset.
    moved : tuple
        Positions in ``open_poles`` of the pendulum pair and the length pole.
    designed : numpy.ndarray
        The three designed discrete poles (pendulum pair, length).
    lqr : LQRDesign
        The LQR design at the same speed (its linear model, trim and named open-loop modes).
    """

    K: np.ndarray
    x_trim: np.ndarray
    wind_speed: float
    dt: float
    zeta: float
    wn: float
    length_time: float
    index: np.ndarray
    Ad: np.ndarray
    Bd: np.ndarray
    open_poles: np.ndarray
    moved: tuple
    designed: np.ndarray
    lqr: LQRDesign = field(repr=False)

    @property
    def K_subset(self) -> np.ndarray:
        return self.K[self.index]

    @property
    def closed_loop_matrix(self) -> np.ndarray:
        """Ad - Bd K of the subset."""
        return self.Ad - self.Bd @ self.K_subset[None, :]

    def expected_poles(self) -> np.ndarray:
        """Open-loop discrete poles with the moved ones replaced by the designed ones."""
        z = self.open_poles.astype(complex).copy()
        for i, zi in zip(self.moved, self.designed, strict=True):
            z[i] = zi
        return z

    def placement_error(self) -> float:
        """Largest distance between the closed-loop poles and :meth:`expected_poles` after
        matching each expected pole to its nearest closed-loop pole (one to one)."""
        return pole_set_distance(np.linalg.eigvals(self.closed_loop_matrix),
                                 self.expected_poles())

    def command(self, dx: np.ndarray) -> float:
        """Unclipped set-point [m/s] for the full-layout state deviation ``dx``."""
        return float(-(self.K[:-1] @ dx))

    def summary(self) -> dict:
        """{label: {"open": {"zeta", "period_s"}, "closed": {...}}} for the pendulum (moved) and
        the pitching and axial-spring modes (unchanged by construction)."""
        out = {}
        for label in ("pendulum", "pitching", "axial spring"):
            m = self.lqr.mode(label, "open")
            opened = ({"zeta": m.zeta, "period_s": m.period} if m is not None
                      else {"zeta": math.nan, "period_s": math.nan})
            out[label] = {"open": opened, "closed": dict(opened)}
        out["pendulum"]["closed"] = {"zeta": self.zeta, "period_s": 2.0 * math.pi / self.wn}
        return out


def pole_set_distance(actual: np.ndarray, expected: np.ndarray) -> float:
    """max_i |expected_i - actual_pi(i)| over the one-to-one matching pi that minimises the
    total distance (Hungarian assignment)."""
    cost = np.abs(expected[:, None] - actual[None, :])
    r, c = linear_sum_assignment(cost)
    return float(np.max(cost[r, c]))


def _moved_modes(lqr: LQRDesign, lam: np.ndarray) -> tuple[complex, int, int]:
    """(pendulum eigenvalue, its position in lam, the length pole's position)."""
    pend = lqr.mode("pendulum", "open")
    if pend is None:
        raise ModalDesignError(f"no open-loop pendulum mode at U = {lqr.wind_speed} m/s")
    i_p = int(np.argmin(np.abs(lam - pend.eigenvalue)))
    i_l = int(np.argmin(np.abs(lam)))
    if abs(lam[i_l]) > 1e-6 * max(1.0, float(np.max(np.abs(lam.real)))):
        raise ModalDesignError(f"the free winch has no neutral length pole (nearest {lam[i_l]})")
    return complex(lam[i_p]), i_p, i_l


def design_modal(params: Params, wind_speed: float, zeta: float | None = None, dt: float = 0.2,
                 *, wn_factor: float = 1.0, length_time: float = DEFAULT_LENGTH_TIME,
                 equilibrium: Equilibrium | None = None, lqr: LQRDesign | None = None
                 ) -> ModalDesign:
    """Place the pendulum pair and the length pole; leave every other mode where it is.

    Parameters
    ----------
    params : Params
        Model parameters.
    wind_speed : float
        Trim wind speed [m/s].
    zeta : float or None
        Pendulum damping ratio to place (default :func:`default_zeta`).
    dt : float
        Control step [s] (zero-order hold).
    wn_factor : float
        Designed natural frequency over the open-loop pendulum's.
    length_time : float
        Time constant of the length-restoring pole [s].
    equilibrium : Equilibrium or None
        A trim at ``wind_speed`` to reuse.
    lqr : LQRDesign or None
        An LQR design at this speed to reuse (its linearisation and mode names).

    Returns
    -------
    ModalDesign

    Raises
    ------
    ModalDesignError
        If the moved modes are not controllable or the placement misses by more than
        :data:`PLACEMENT_TOL`.
    """
    zeta = default_zeta(wind_speed) if zeta is None else float(zeta)
    _check_target(zeta, wn_factor, length_time)
    eq = equilibrium or find_equilibrium(params, float(wind_speed))
    lqr = lqr or design_lqr(params, float(wind_speed), dt, equilibrium=eq)
    idx = lqr.mode_index[:-1]  # longitudinal + L, v_w (the LQR's subset without the integral)
    A = lqr.linear.A_free[np.ix_(idx, idx)]
    Ad, Bd = discretize(A, lqr.linear.B[idx], dt)
    lam = np.linalg.eigvals(A)
    lam_p, i_p, i_l = _moved_modes(lqr, lam)
    w_p, w_l = left_eigenvector(A, lam_p), np.real(left_eigenvector(A, 0.0))
    T = np.vstack([w_p.real, w_p.imag, w_l])
    z_p, z_l = complex(np.exp(lam_p * dt)), 1.0
    Lam = real_modal_block(z_p, z_l)
    b = T @ Bd[:, 0]
    wn = abs(lam_p) * wn_factor
    target = np.array([pendulum_target(wn, zeta, dt), 0.0, math.exp(-dt / length_time)],
                      dtype=complex)
    target[1] = target[0].conjugate()
    C = np.column_stack([b, Lam @ b, Lam @ Lam @ b])
    if np.linalg.cond(C) > 1e12:
        raise ModalDesignError(f"pendulum and length poles not controllable from the winch at "
                               f"U = {wind_speed} m/s (cond {np.linalg.cond(C):.2e})")
    k = ackermann(Lam, b, target)
    K = np.zeros(lqr.K.size)
    K[idx] = k @ T
    i_conj = int(np.argmin(np.abs(lam - lam_p.conjugate()) + (np.arange(lam.size) == i_p)))
    design = ModalDesign(K=K, x_trim=lqr.x_trim.copy(), wind_speed=float(wind_speed),
                         dt=float(dt), zeta=zeta, wn=wn, length_time=float(length_time),
                         index=idx, Ad=Ad, Bd=Bd, open_poles=np.exp(lam * dt),
                         moved=(i_p, i_conj, i_l), designed=target, lqr=lqr)
    err = design.placement_error()
    if not err < PLACEMENT_TOL:
        raise ModalDesignError(f"modal placement at U = {wind_speed} m/s missed by {err:.2e}")
    return design


class ModalSchedule(LQRSchedule):
    """Table of modal designs over mean wind speed; gains interpolated linearly in U (the
    lookup, :meth:`gain`, is :class:`LQRSchedule`'s).

    Parameters
    ----------
    params : Params
        Model parameters.
    speeds : array_like or None
        Design wind speeds [m/s], increasing (default 2 to 16 m/s in 1 m/s steps).
    dt : float
        Control step [s].
    zeta : float, callable or None
        Pendulum target: one damping ratio for every speed, a function of U, or None for
        :func:`default_zeta`.
    wn_factor : float
        Designed natural frequency over the open-loop pendulum's.
    length_time : float
        Time constant of the length loop [s].
    """

    def __init__(self, params: Params, speeds=None, dt: float = 0.2, zeta=None, *,
                 wn_factor: float = 1.0, length_time: float = DEFAULT_LENGTH_TIME):
        target = zeta if callable(zeta) else (default_zeta if zeta is None
                                              else (lambda _u: float(zeta)))
        designs = self._build(params, speeds, dt, lambda U, eq: design_modal(
            params, U, target(U), dt, wn_factor=wn_factor, length_time=length_time,
            equilibrium=eq))
        self.weights = {"zeta": [d.zeta for d in designs], "wn_factor": float(wn_factor),
                        "length_time": float(length_time)}
        self.subsets = ["long"] * len(designs)


class ModalPolicy(LQRPolicy):
    """The gain-scheduled modal controller as an SB3-style policy over the full observation.

    Parameters
    ----------
    params : Params
        Parameters of the environment.
    dt : float
        Control step [s] (must match the schedule's).
    schedule : ModalSchedule or None
        The gain table (default: built here over 2-16 m/s with :func:`default_zeta`).

    Notes
    -----
    ``predict`` is :meth:`LQRPolicy.predict`: v = -K(U) dx from the privileged full state and
    the episode's mean wind speed, clipped to +-max_speed. The integral gain is zero, so the
    integral state the LQR policy carries is inert here; the length loop is the placed pole.

    It reads the raw deviation, not the swing plane (:attr:`LQRPolicy.swing_plane` off): it
    moves only the pendulum pole pair, and where the LQR pumps a lateral swing (0.05 x the
    baseline's volume on 60 m, 10 m/s, 5-20 m lateral starts) it lets the swing decay as fast
    as the braked winch does. Its stored frontier and report rows are kept as they are.
    """

    swing_plane = False

    def __init__(self, params: Params, dt: float = 0.2, schedule: ModalSchedule | None = None):
        super().__init__(params, dt=dt,
                         schedule=schedule if schedule is not None else ModalSchedule(params,
                                                                                      dt=dt))
