"""Output-feedback winch controllers: a steady-state Kalman filter on the standard observation
channels (the ones a learned policy sees, with the environment's sensor noise) and a
gain-scheduled state feedback acting on the estimate: the LQR's gains (``gains="lqr"``, the
``lqg`` baseline) or the modal pole placement's (``gains="modal"``, the ``modal_lqg`` baseline:
the frontier controller on equal information with a learned policy).

Design at one mean wind speed U (:func:`design_lqg`):

1. the state feedback on the longitudinal + winch subset (the lateral states are uncontrollable
   from the winch and get no gain): the LQR of :func:`aerostat_gym.agents.lqr.design_lqr`
   (``subset="long"``) with its integral of the length error, or the modal design of
   :func:`aerostat_gym.agents.modal.design_modal` on the same linear model (no integral: its
   length loop is a placed pole);
2. the same subset's zero-order-hold model x_{k+1} = Ad x_k + Bd u_k + w_k (u the set-point);
3. measurements y = C x + v from the standard observation (:data:`MEASURED`): CM displacement
   and velocity along the wind and up, pitch, pitch rate, winch tension minus trim (its row is
   the finite-difference gradient of the compiled winch-end tension), paid-out length and reel
   speed, each in SI units (channel value times its scale);
4. measurement noise R = diag((sigma scale_k)^2): the environment adds Gaussian noise of std
   ``obs_noise`` in scaled units to every standard channel, so sigma is that ``obs_noise``
   (floored at :data:`MIN_NOISE` so that R stays positive definite for a noise-free env);
5. process noise W = diag(q_i^2) from :data:`DEFAULT_PROCESS_NOISE`: the per-step random change
   of each state that the turbulence and the unmodelled nonlinearity cause (largest on the
   velocities, where the gust forces enter);
6. the filter Riccati equation (the dual DARE, :func:`scipy.linalg.solve_discrete_are` on
   (Ad^T, C^T)) gives the a-priori covariance P and the gain L = P C^T (C P C^T + R)^-1.

Filter, once per control step: predict x- = Ad x^ + Bd u_prev, correct x^ = x- + L (y - C x-).
The estimation error e = x - x^ then obeys e_k = (I - L C) Ad e_{k-1} + noise terms, so without
noise it decays with the eigenvalues of (I - L C) Ad: the designed estimator rate
(:attr:`LQGDesign.estimator_poles`). By the separation principle the closed loop's poles are the
state feedback's and the estimator's, so its linear pendulum damping is the LQR's (or the
modal design's placed ratio).

The schedule interpolates every matrix linearly in U, and U itself is estimated from the
measured along-wind air velocity at the aerostat (channel 16), low-passed with time constant
:data:`WIND_TIME_CONSTANT`: no privileged information reaches the policy.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as sla

from ..analysis.linear import state_steps
from ..analysis.trim import find_equilibrium
from ..envs.spaces import CHANNELS, N_OBS, OBS_INDEX, OBS_WIND_X, as_batch, check_obs_noise
from ..params import Params
from ..physics.state import S_Q, S_THETA, S_VX, S_VZ, S_X, S_Z, StateLayout
from ..sim import Model
from .lqr import LQRDesign, design_lqr, discretize
from .modal import design_modal
from .scheduling import DEFAULT_SPEEDS, held_trims, scheduled_tables
from .state_check import check_state_passed

#: Standard observation channels the filter uses (name -> index), all longitudinal.
MEASURED = {name: OBS_INDEX[name] for name in ("dx", "dz", "vx", "vz", "dpitch", "q",
                                               "dtension", "dlength", "reel_speed")}
#: The features :meth:`LQGPolicy.estimate_features` gives: each measured channel as the
#: filter's estimate reconstructs it, then the set-point just sent.
ESTIMATE_FEATURES = tuple(f"{name}_estimate" for name in MEASURED) + ("base_command",)
#: Channel of the measured along-wind air velocity (the wind-speed estimate for the schedule).
WIND_CHANNEL = OBS_WIND_X
#: Time constant of the wind-speed estimate [s].
WIND_TIME_CONSTANT = 20.0
#: State feedbacks the filter's estimate can drive (``gains``).
GAINS = ("lqr", "modal")
#: Sensor noise the filter is designed for when the environment's obs_noise is 0 (scaled units).
MIN_NOISE = 1.0e-3
#: Per-step process-noise standard deviation of each state group (SI units).
DEFAULT_PROCESS_NOISE = {
    "node_pos": 0.01,  # m
    "node_vel": 0.05,  # m/s, gust drag on the tether
    "cm_pos": 0.01,  # m
    "cm_vel": 0.05,  # m/s, gust forces on the hull
    "pitch": 1.0e-3,  # rad
    "pitch_rate": 5.0e-3,  # rad/s, gust moments
    "length": 1.0e-3,  # m (1e-4 leaves the neutral length estimate a 48 s time constant)
    "reel_speed": 1.0e-3,  # m/s
}


def _process_noise(layout: StateLayout, idx: np.ndarray, noise: dict) -> np.ndarray:
    """W = diag(q^2) over the subset ``idx`` (full-layout indices)."""
    unknown = sorted(set(noise) - set(DEFAULT_PROCESS_NOISE))
    if unknown:
        raise ValueError(f"unknown process-noise group(s) {unknown}; known: "
                         f"{list(DEFAULT_PROCESS_NOISE)}")
    q = {**DEFAULT_PROCESS_NOISE, **noise}
    for k, v in q.items():
        if not (isinstance(v, float | int) and math.isfinite(v) and v > 0):
            raise ValueError(f"process noise {k!r} must be finite and > 0, got {v!r}")
    s = np.zeros(layout.size)
    s[layout.node_pos] = q["node_pos"]
    s[layout.node_vel] = q["node_vel"]
    s[layout.cm_pos] = q["cm_pos"]
    s[layout.cm_vel] = q["cm_vel"]
    s[layout.euler] = q["pitch"]
    s[layout.rates] = q["pitch_rate"]
    s[layout.winch_length] = q["length"]
    s[layout.winch_speed] = q["reel_speed"]
    return np.diag(s[idx] ** 2)


def tension_gradient(params: Params, x_trim: np.ndarray, wind_speed: float, idx: np.ndarray,
                     eps: float = 1e-5) -> np.ndarray:
    """d T_winch / d x over the subset ``idx`` by central differences of the compiled
    winch-end tension (steps of :func:`aerostat_gym.analysis.linear.state_steps`)."""
    model = Model(params, wind=wind_speed)
    h = state_steps(x_trim, eps)
    g = np.empty(idx.size)
    for k, j in enumerate(idx):
        xp, xm = x_trim.copy(), x_trim.copy()
        xp[j] += h[j]
        xm[j] -= h[j]
        g[k] = (model.end_tensions(xp)[1] - model.end_tensions(xm)[1]) / (2.0 * h[j])
    return g


def measurement_matrix(params: Params, lqr: LQRDesign, idx: np.ndarray) -> np.ndarray:
    """C (len(MEASURED), len(idx)): SI measurements as linear functions of the subset state."""
    lay = lqr.linear.layout
    pos = {j: k for k, j in enumerate(idx)}
    direct = {"dx": lay.at(S_X), "dz": lay.at(S_Z), "vx": lay.at(S_VX),
              "vz": lay.at(S_VZ), "dpitch": lay.at(S_THETA),
              "q": lay.at(S_Q), "dlength": lay.winch_length,
              "reel_speed": lay.winch_speed}
    C = np.zeros((len(MEASURED), idx.size))
    for r, name in enumerate(MEASURED):
        if name == "dtension":
            C[r] = tension_gradient(params, lqr.x_trim, lqr.wind_speed, idx)
        else:
            C[r, pos[direct[name]]] = 1.0
    return C


def measurement_noise(obs_noise: float) -> np.ndarray:
    """R = diag((sigma scale_k)^2) for the measured channels, sigma = max(obs_noise,
    MIN_NOISE) in the environment's scaled units."""
    sigma = max(check_obs_noise(obs_noise), MIN_NOISE)
    return np.diag([(sigma * CHANNELS[i].scale) ** 2 for i in MEASURED.values()])


def kalman_gain(Ad: np.ndarray, C: np.ndarray, W: np.ndarray, R: np.ndarray
                ) -> tuple[np.ndarray, np.ndarray]:
    """(P, L): a-priori steady-state covariance from the filter DARE and the correction gain
    L = P C^T (C P C^T + R)^-1."""
    P = sla.solve_discrete_are(Ad.T, C.T, W, R)
    P = 0.5 * (P + P.T)
    L = np.linalg.solve(C @ P @ C.T + R, C @ P).T
    return P, L


@dataclass
class LQGDesign:
    """One LQG design at mean wind speed ``wind_speed`` (subset: longitudinal + L, v_w).

    Attributes
    ----------
    lqr : LQRDesign
        The state-feedback design (subset "long").
    index : numpy.ndarray
        Full-layout indices of the subset.
    Ad : numpy.ndarray
        Discrete open-loop matrix of the subset.
    Bd : numpy.ndarray
        Discrete input column of the subset, (n, 1).
    C : numpy.ndarray
        Measurement matrix (SI units).
    R : numpy.ndarray
        Measurement-noise covariance.
    W : numpy.ndarray
        Process-noise covariance.
    P : numpy.ndarray
        A-priori steady-state error covariance.
    L : numpy.ndarray
        Correction gain.
    K : numpy.ndarray
        State gain over the subset.
    K_integral : float
        Gain on the integral of the length error.
    obs_noise : float
        Sensor noise (scaled units) the filter was designed for.
    gains : str
        The state feedback: "lqr" or "modal".
    modes : dict
        The state feedback's predicted modes (its ``summary()``).
    """

    lqr: LQRDesign = field(repr=False)
    index: np.ndarray
    Ad: np.ndarray
    Bd: np.ndarray
    C: np.ndarray
    R: np.ndarray
    W: np.ndarray
    P: np.ndarray
    L: np.ndarray
    K: np.ndarray
    K_integral: float
    obs_noise: float
    gains: str = "lqr"
    modes: dict = field(default_factory=dict)

    @property
    def wind_speed(self) -> float:
        return self.lqr.wind_speed

    @property
    def error_matrix(self) -> np.ndarray:
        """(I - L C) Ad: one step of the noise-free estimation error."""
        return (np.eye(self.Ad.shape[0]) - self.L @ self.C) @ self.Ad

    @property
    def estimator_poles(self) -> np.ndarray:
        """Discrete eigenvalues of the estimation error dynamics."""
        return np.linalg.eigvals(self.error_matrix)

    def summary(self) -> dict:
        """The state feedback's predicted modes (separation principle: the closed loop's
        pendulum, pitching and axial-spring modes are the state feedback's), plus the slowest
        estimator pole."""
        z = self.estimator_poles
        zmax = z[np.argmax(np.abs(z))]
        s = np.log(complex(zmax)) / self.lqr.dt
        return {**self.modes,
                "estimator": {"spectral_radius": float(abs(zmax)),
                              "slowest_time_constant_s": float(-1.0 / s.real)}}


def design_lqg(params: Params, wind_speed: float, dt: float = 0.2, obs_noise: float = 0.0, *,
               process_noise: dict | None = None, weights: dict | None = None,
               equilibrium=None, gains: str = "lqr") -> LQGDesign:
    """Kalman filter + state feedback at one wind speed (see the module docstring).

    Parameters
    ----------
    params : Params
        Model parameters.
    wind_speed : float
        Trim wind speed [m/s].
    dt : float
        Control step [s].
    obs_noise : float
        The environment's sensor noise std in its scaled units.
    process_noise : dict or None
        Overrides of :data:`DEFAULT_PROCESS_NOISE`.
    weights : dict or None
        LQR weight overrides (:data:`aerostat_gym.agents.lqr.DEFAULT_WEIGHTS`).
    equilibrium : Equilibrium or None
        A trim at ``wind_speed`` to reuse.
    gains : str
        "lqr" (the LQR's gains and length integral) or "modal" (the modal pole placement at
        :func:`aerostat_gym.agents.modal.default_zeta`, no integral).

    Returns
    -------
    LQGDesign
    """
    if gains not in GAINS:
        raise ValueError(f"gains must be one of {GAINS}, got {gains!r}")
    eq = equilibrium or find_equilibrium(params, float(wind_speed))
    lqr = design_lqr(params, float(wind_speed), dt, weights, equilibrium=eq, subset="long")
    idx = lqr.mode_index[:-1]
    if gains == "modal":
        modal = design_modal(params, float(wind_speed), dt=dt, equilibrium=eq, lqr=lqr)
        K, K_integral, modes = modal.K[idx].copy(), 0.0, modal.summary()
    else:
        K, K_integral, modes = lqr.K[idx].copy(), lqr.K_integral, lqr.summary()
    Ad, Bd = discretize(lqr.linear.A_free[np.ix_(idx, idx)], lqr.linear.B[idx], dt)
    C = measurement_matrix(params, lqr, idx)
    R = measurement_noise(obs_noise)
    W = _process_noise(lqr.linear.layout, idx, process_noise or {})
    P, L = kalman_gain(Ad, C, W, R)
    return LQGDesign(lqr=lqr, index=idx, Ad=Ad, Bd=Bd, C=C, R=R, W=W, P=P, L=L,
                     K=K, K_integral=float(K_integral), obs_noise=float(obs_noise), gains=gains,
                     modes=modes)


#: The schedule's tables that are feedback gains (faded at low wind), not the filter's.
FEEDBACK_TABLES = frozenset({"K", "K_integral"})


class LQGSchedule:
    """LQG designs over mean wind speed; every matrix interpolated linearly in U (clamped; the
    gains faded below the lowest speed, :meth:`lookup`).

    Parameters
    ----------
    params : Params
        Model parameters.
    speeds : array_like or None
        Design speeds [m/s], increasing (default 2 to 16 m/s in 1 m/s steps); those whose
        trim the winch motor cannot hold are dropped
        (:func:`~aerostat_gym.agents.scheduling.held_trims`).
    dt : float
        Control step [s].
    obs_noise : float
        Sensor noise the filters are designed for (scaled units).
    process_noise : dict or None
        Overrides of :data:`DEFAULT_PROCESS_NOISE`.
    gains : str
        The state feedback on the estimate, "lqr" or "modal" (:func:`design_lqg`).
    """

    def __init__(self, params: Params, speeds=None, dt: float = 0.2, obs_noise: float = 0.0,
                 process_noise: dict | None = None, gains: str = "lqr"):
        held = held_trims(params, DEFAULT_SPEEDS if speeds is None else speeds)
        designs = [design_lqg(params, U, dt, obs_noise, process_noise=process_noise,
                              equilibrium=eq, gains=gains) for U, eq in held]
        self.params, self.dt, self.designs = params, float(dt), designs
        self.speeds = np.array([U for U, _ in held])
        self.index = designs[0].index
        self.tables = {name: np.array([getattr(d, name) for d in designs])
                       for name in ("Ad", "Bd", "C", "L", "K")}
        self.tables["K_integral"] = np.array([d.K_integral for d in designs])

    def lookup(self, U: np.ndarray, names=None) -> dict:
        """The tables ``names`` (default every one) at the speeds U (N,), linear in U between
        the design speeds; the feedback gains (K, K_integral) faded below the lowest one, the
        filter's tables not (:func:`~aerostat_gym.agents.scheduling.scheduled_tables`)."""
        tables = {k: self.tables[k] for k in (names or self.tables)}
        return scheduled_tables(self.speeds, tables, U, FEEDBACK_TABLES)


class LQGPolicy:
    """The LQG as an SB3-style policy on the standard 19-channel observation.

    Parameters
    ----------
    params : Params
        Parameters of the environment.
    dt : float
        Control step [s] (must match the schedule's).
    obs_noise : float
        The environment's sensor noise (scaled units); designs the filters.
    schedule : LQGSchedule or None
        The design table (default: built here over 2-16 m/s).
    gains : str
        The state feedback of the default table, "lqr" or "modal".

    Notes
    -----
    ``state`` is an (N, n + 3) array per environment: the estimate x^ (n subset states), the
    length-error integral z, the wind-speed estimate and the last set-point sent. On
    ``episode_start`` the estimate restarts from x- = 0 (the trim) corrected by the first
    measurement, the integral from 0 and the wind estimate from the first air-velocity reading.
    The integral is conditional (no integration while saturated in the direction it pushes),
    as in :class:`aerostat_gym.agents.lqr.LQRPolicy`.
    """

    obs_dim = N_OBS
    n_features = len(ESTIMATE_FEATURES)

    def __init__(self, params: Params, dt: float = 0.2, obs_noise: float = 0.0,
                 schedule: LQGSchedule | None = None, gains: str = "lqr"):
        self.params = params
        self.dt = float(dt)
        self.schedule = schedule or LQGSchedule(params, dt=dt, obs_noise=obs_noise, gains=gains)
        if abs(self.schedule.dt - self.dt) > 1e-12:
            raise ValueError(f"schedule was designed for dt = {self.schedule.dt} s, policy "
                             f"dt = {self.dt} s")
        self.max_speed = float(params.winch.max_speed)
        self.n = self.schedule.index.size
        self.scale = np.array([CHANNELS[i].scale for i in MEASURED.values()])
        self.channels = np.array(list(MEASURED.values()))
        self.i_length = list(MEASURED).index("dlength")

    def _state(self, state, N: int) -> np.ndarray:
        if state is None:
            return np.full((N, self.n + 3), np.nan)
        S = np.array(state, dtype=float)
        if S.size != N * (self.n + 3):  # a state of another batch size or another policy
            raise ValueError(f"LQG state must have shape ({N}, {self.n + 3}) for {N} "
                             f"observation(s), got {np.shape(state)}: pass back the state "
                             "that predict returned for this batch")
        return S.reshape(N, self.n + 3)

    def predict(self, observation, state=None, episode_start=None, deterministic: bool = True):
        """(actions, state): actions (1,) or (N, 1) float32 in [-1, 1]; state to pass back."""
        obs2, single = as_batch(observation, float, episode_start)
        check_state_passed(self, state, episode_start, len(obs2), "the Kalman filter's "
                           "estimate, the wind filter and the length integral")
        if obs2.ndim != 2 or obs2.shape[1] < N_OBS:
            raise ValueError(f"LQGPolicy needs the standard observation ({N_OBS} channels), got "
                             f"shape {np.shape(observation)}")
        N = obs2.shape[0]
        S = self._state(state, N)
        start = np.isnan(S[:, 0])
        if episode_start is not None:
            start |= np.asarray(episode_start, bool).reshape(-1)
        wind = obs2[:, WIND_CHANNEL] * CHANNELS[WIND_CHANNEL].scale
        S[start] = 0.0
        S[start, self.n + 1] = wind[start]
        U = S[:, self.n + 1] + (self.dt / WIND_TIME_CONSTANT) * (wind - S[:, self.n + 1])
        U[start] = wind[start]
        m = self.schedule.lookup(U)
        y = obs2[:, self.channels] * self.scale
        x_pred = np.einsum("nij,nj->ni", m["Ad"], S[:, :self.n]) + m["Bd"][..., 0] * S[:, -1:]
        x_pred[start] = 0.0
        innov = y - np.einsum("nij,nj->ni", m["C"], x_pred)
        x_hat = x_pred + np.einsum("nij,nj->ni", m["L"], innov)
        z = S[:, self.n]
        kz = m["K_integral"]
        v = -np.einsum("ni,ni->n", m["K"], x_hat) - kz * z
        v_cmd = np.clip(v, -self.max_speed, self.max_speed)
        dz = self.dt * y[:, self.i_length]
        push = -kz * dz
        wind_up = ((v >= self.max_speed) & (push > 0)) | ((v <= -self.max_speed) & (push < 0))
        S_next = np.column_stack([x_hat, np.where(wind_up, z, z + dz), U, v_cmd])
        actions = np.clip(v_cmd / self.max_speed, -1.0, 1.0).astype(np.float32)[:, None]
        return (actions[0] if single else actions), S_next

    def estimate_features(self, state) -> np.ndarray:
        """What the filter knows after a step, for a learned residual to read
        (:data:`ESTIMATE_FEATURES`): the measured channels reconstructed from the estimate,
        C(U) x^, in the observation's scaled units (the sensor noise filtered out, the
        pendulum's phase in the displacement and velocity pair), and the set-point just sent
        as a fraction of the winch's top speed; (N, 10) float32 from the (N, n + 3)
        ``state`` that :meth:`predict` returned."""
        S = np.asarray(state, dtype=float)
        C = self.schedule.lookup(S[:, self.n + 1], ("C",))["C"]
        y_hat = np.einsum("nij,nj->ni", C, S[:, :self.n]) / self.scale
        return np.column_stack([y_hat, S[:, -1] / self.max_speed]).astype(np.float32)

    def predicted_modes(self, wind_speed: float) -> dict:
        """The design nearest ``wind_speed``: LQR modes and the slowest estimator pole."""
        k = int(np.argmin(np.abs(self.schedule.speeds - wind_speed)))
        return {"design_wind_speed": float(self.schedule.speeds[k]),
                **self.schedule.designs[k].summary()}
