"""Gain-scheduled discrete LQR on the winch reel speed, with integral action on tether length.

Design (:func:`design_lqr`) at one mean wind speed U:

1. trim (:func:`aerostat_gym.analysis.trim.find_equilibrium`) at the configured tether length;
2. linearize with the brake released and the speed loop holding v_set = 0
   (:func:`aerostat_gym.analysis.linear.linearize`: ``A_free``, 6n+8 states, and ``B``, input
   v_set in m/s);
3. discretise at the control step dt with a zero-order hold (matrix exponential of the augmented
   matrix [[A, B], [0, 0]] dt), which is exactly what the simulator and the environment apply:
   one set-point held over each control interval;
4. augment an integral state on the tether-length deviation, z_{k+1} = z_k + dt (L_k - L0), so a
   constant disturbance (a wind-speed error in the schedule, a length offset) leaves no
   steady length error;
5. Bryson weights Q = diag(1 / dx_max^2), R = 1 / v_max^2 (:data:`LQR_MAX_DEVIATIONS`), solve the
   discrete algebraic Riccati equation (:func:`scipy.linalg.solve_discrete_are`) and form
   K = (R + B^T P B)^-1 B^T P A. The command is v_set = -K [x - x_trim; z].

Controllability: the winch enters only the longitudinal equations. For an aerostat symmetric
about its xz-plane, trimmed in that plane, the lateral states (y, phi, psi and their rates) are
uncontrollable from the winch (B is exactly zero there and the lateral/longitudinal coupling of
A_free is at rounding level, ~1e-14). The DARE only needs (A, B) stabilizable: the lateral modes
are stable in wind, so the full 6n+9-state problem is solvable and its lateral gains come out at
rounding level (~1e-11). ``subset="auto"`` (default) designs on the full model and falls back to
the longitudinal + winch subset (lateral gains exactly zero) if the full DARE fails, e.g. near
zero wind where the yaw mode is neutral; ``subset="long"`` forces the subset design.

Closed-loop modes: the eigenvalues z of the closed-loop discrete matrix are mapped to continuous
equivalents s = ln(z) / dt (modes above the Nyquist rate pi / dt alias, as they must in any
sampled loop) and classified with :mod:`aerostat_gym.analysis.modes` on the longitudinal part of
their eigenvectors; the pendulum, pitching and axial-spring modes are then matched to the braked
[LN02] modes by eigenvector similarity (MAC) and frequency, because the winch/integral loop adds
a slow mode that the energy rule alone would also call "axial spring" or "pendulum".
"""

from __future__ import annotations

import json
import math
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import scipy.linalg as sla

from ..analysis.linear import LinearModel, decouple, linearize
from ..analysis.modes import (
    AEROSTAT_MODES,
    Mode,
    ModeContext,
    energy_vector,
    mac,
    modal_table,
    mode_context,
    modes_from_eig,
)
from ..analysis.trim import Equilibrium, find_equilibrium
from ..checks import is_finite_number
from ..envs.spaces import OBS_FULL_STATE, OBS_FULL_WIND, as_batch
from ..params import Params
from ..physics.state import S_PSI, StateLayout
from .privileged import full_observation as full_observation  # the 'as' imports: names
from .privileged import set_point_law as set_point_law  # importable from lqr as before 0.7.16
from .scheduling import (
    DEFAULT_SPEEDS,
    LQRDesignError,
    held_trims,
    params_fingerprint,
    schedule_speeds,
    scheduled_tables,
)
from .scheduling import SCHEDULE_STEP as SCHEDULE_STEP
from .scheduling import low_wind_fade as low_wind_fade
from .state_check import check_state_passed
from .swing_plane import in_swing_plane

#: Bryson "largest acceptable deviation" of each state group (SI units), the integral of the
#: length error [m s], and the set-point (``None``: params.winch.max_speed). Q_ii = 1 / value^2.
#: CM displacement 5 m and velocity 0.5 m/s weight the pendulum enough that the loop adds
#: damping to it; pitch 0.1 rad and pitch rate 0.05 rad/s keep the pitch gains at a few
#: (m/s)/rad (0.05 rad and 0.02 rad/s give gains near 20 (m/s)/(rad/s) at 5 m/s, which chatter
#: the winch on pitch oscillations and ride its 0.5 m/s^2 acceleration limit). Tether nodes get
#: small weights: their motion follows the aerostat's and the winch cannot shape it. An
#: override of the CM groups may give one deviation per axis, (x, y, z) in the ground frame:
#: a design can then weight the along-wind displacement alone and leave the height free.
LQR_MAX_DEVIATIONS: dict[str, float | None] = {
    "node_pos": 50.0,  # m, every moving tether node, x y z
    "node_vel": 10.0,  # m/s
    "cm_pos": 5.0,  # m, aerostat CM x y z
    "cm_vel": 0.5,  # m/s
    "roll": 0.1,  # rad
    "pitch": 0.1,  # rad
    "yaw": 0.1,  # rad
    "roll_rate": 0.05,  # rad/s
    "pitch_rate": 0.05,  # rad/s
    "yaw_rate": 0.05,  # rad/s
    "length": 5.0,  # m, paid-out tether length
    "reel_speed": None,  # m/s, winch reel speed v_w (None: params.winch.max_speed)
    "length_integral": 50.0,  # m s, integral of the length error
    "v_set": None,  # m/s, set-point (None: params.winch.max_speed)
}
#: The deviations above are for the 300 m baseline tether. For another configuration the
#: positions (and the length integral) scale with tether.length / WEIGHTS_REFERENCE_LENGTH and
#: the velocities and rates with its square root, as the pendulum's amplitude and frequency do
#: (omega ~ sqrt(g' / L)); angles are not scaled. The baseline's weights are unchanged.
WEIGHTS_REFERENCE_LENGTH = 300.0
_POSITION_WEIGHTS = ("node_pos", "cm_pos", "length", "length_integral")
_VELOCITY_WEIGHTS = ("node_vel", "cm_vel", "roll_rate", "pitch_rate", "yaw_rate")


#: Long-period/short-period modes reported by :meth:`LQRDesign.summary`.
NAMED_MODES = ("pendulum", "pitching", "axial spring")



def scaled_deviations(params: Params) -> dict:
    """:data:`LQR_MAX_DEVIATIONS` for the configured tether and winch (see
    :data:`WEIGHTS_REFERENCE_LENGTH`); the reel speed and set-point at winch.max_speed."""
    r = params.tether.length / WEIGHTS_REFERENCE_LENGTH
    w = dict(LQR_MAX_DEVIATIONS)
    for k in _POSITION_WEIGHTS:
        w[k] = w[k] * r
    for k in _VELOCITY_WEIGHTS:
        w[k] = w[k] * math.sqrt(r)
    for k in ("reel_speed", "v_set"):
        w[k] = float(params.winch.max_speed)
    return w


#: Weight groups that take one deviation per ground axis (x, y, z) as well as one for all three.
PER_AXIS_WEIGHTS = ("cm_pos", "cm_vel")


def _deviation(v) -> bool:
    return is_finite_number(v) and v > 0


def _weights(params: Params, weights: dict | None) -> dict:
    w = scaled_deviations(params)
    for k, v in (weights or {}).items():
        if k not in w:
            raise ValueError(f"unknown LQR weight {k!r}; known: {', '.join(w)}")
        w[k] = v
    out = {}
    for k, v in w.items():
        if k in PER_AXIS_WEIGHTS and isinstance(v, list | tuple):
            if not (len(v) == 3 and all(_deviation(a) for a in v)):
                raise ValueError(f"LQR weight {k!r} must be a finite positive deviation or three "
                                 f"of them (x, y, z), got {v!r}")
            out[k] = tuple(float(a) for a in v)
        elif _deviation(v):
            out[k] = float(v)
        else:
            raise ValueError(f"LQR weight {k!r} must be a finite positive deviation, got {v!r}")
    return out


def bryson_weights(layout: StateLayout, weights: dict) -> tuple[np.ndarray, np.ndarray]:
    """Q (diagonal, 6n+9 incl. the integral state) and R (1x1) from maximum deviations."""
    m = np.empty(layout.size + 1)
    m[layout.node_pos] = weights["node_pos"]
    m[layout.node_vel] = weights["node_vel"]
    m[layout.cm_pos] = weights["cm_pos"]
    m[layout.cm_vel] = weights["cm_vel"]
    m[layout.euler] = [weights["roll"], weights["pitch"], weights["yaw"]]
    m[layout.rates] = [weights["roll_rate"], weights["pitch_rate"], weights["yaw_rate"]]
    m[layout.winch_length] = weights["length"]
    m[layout.winch_speed] = weights["reel_speed"]
    m[-1] = weights["length_integral"]
    return np.diag(1.0 / m**2), np.array([[1.0 / weights["v_set"] ** 2]])


def discretize(A: np.ndarray, B: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """Zero-order-hold discretisation: expm([[A, B], [0, 0]] dt) = [[Ad, Bd], [0, I]]."""
    n, m = B.shape
    M = np.zeros((n + m, n + m))
    M[:n, :n] = A * dt
    M[:n, n:] = B * dt
    E = sla.expm(M)
    return E[:n, :n], E[:n, n:]


def augment(Ad: np.ndarray, Bd: np.ndarray, layout: StateLayout, dt: float
            ) -> tuple[np.ndarray, np.ndarray]:
    """Append z_{k+1} = z_k + dt (L_k - L0) to the discrete model."""
    n = Ad.shape[0]
    Aa = np.zeros((n + 1, n + 1))
    Aa[:n, :n] = Ad
    Aa[n, layout.winch_length] = dt
    Aa[n, n] = 1.0
    return Aa, np.vstack([Bd, np.zeros((1, Bd.shape[1]))])


def dare_gain(A: np.ndarray, B: np.ndarray, Q: np.ndarray, R: np.ndarray
              ) -> tuple[np.ndarray, np.ndarray]:
    """(P, K) of the discrete LQR: P from the DARE, K = (R + B^T P B)^-1 B^T P A."""
    P = sla.solve_discrete_are(A, B, Q, R)
    P = 0.5 * (P + P.T)
    K = np.linalg.solve(R + B.T @ P @ B, B.T @ P @ A)
    return P, K


def riccati_residual(A, B, Q, R, P) -> float:
    """max |A^T P A - P - A^T P B (R + B^T P B)^-1 B^T P A + Q| / max |P|."""
    G = A.T @ P @ B
    res = A.T @ P @ A - P - G @ np.linalg.solve(R + B.T @ P @ B, G.T) + Q
    return float(np.max(np.abs(res)) / np.max(np.abs(P)))


# --- modes ----------------------------------------------------------------------------------------


def _name_modes(modes: list[Mode], reference: list[Mode], ctx: ModeContext) -> None:
    """Give each aerostat mode label (pendulum, pitching, axial spring) to the oscillatory mode
    most like the braked reference mode of that label (cost 1 - MAC + 0.5 |ln(wn / wn_ref)|);
    other modes that the energy rule gave one of these labels are the winch's own (the length
    integrator or lag, and with the LQR the length/integral loop) and are renamed "winch".
    In place."""
    chosen = {}
    for label in AEROSTAT_MODES["long"]:
        ref = next((m for m in reference if m.label == label), None)
        if ref is None:
            continue
        rv = energy_vector(ref.vector, ctx)
        cands = [m for m in modes if m.oscillatory and id(m) not in chosen.values()]
        if not cands:
            continue
        cost = [1.0 - mac(rv, energy_vector(m.vector, ctx))
                + 0.5 * abs(math.log(max(m.wn, 1e-9) / ref.wn)) for m in cands]
        chosen[label] = id(cands[int(np.argmin(cost))])
    ids = {v: k for k, v in chosen.items()}
    for m in modes:
        if id(m) in ids:
            m.label = ids[id(m)]
        elif m.label in AEROSTAT_MODES["long"]:
            m.label = "winch"


# --- design ---------------------------------------------------------------------------------------


@dataclass
class LQRDesign:
    """One discrete LQR design at mean wind speed ``wind_speed``.

    Attributes
    ----------
    K : (6n+9,) gain over [x - x_trim; z]; v_set = -K @ [dx; z] in m/s.
    x_trim : trim state (6n+8). wind_speed : U [m/s]. dt : control step [s].
    weights : the Bryson deviations used. subset : "full" or "long" (which DARE was solved).
    A, B : augmented discrete model (6n+9 square, 6n+9 x 1), full layout plus z last.
    Q, R : weights of the solved problem; P : its DARE solution; index : the augmented-state
    indices of the solved problem (all of them for "full").
    closed_loop, open_loop : longitudinal + winch modes (continuous equivalents; the closed loop
    includes the integral state; open loop = brake released, speed loop holding v_set = 0).
    braked : the [LN02] braked longitudinal modes (the naming reference).
    closed_loop_eigenvalues : all 6n+9 closed-loop eigenvalues, continuous equivalents.
    mode_index : augmented-state indices of the closed-loop mode vectors (longitudinal subset
    order, then L, v_w, z).
    linear : the continuous linear model. equilibrium : the trim.
    """

    K: np.ndarray
    x_trim: np.ndarray
    wind_speed: float
    dt: float
    weights: dict
    subset: str
    A: np.ndarray
    B: np.ndarray
    Q: np.ndarray
    R: np.ndarray
    P: np.ndarray
    index: np.ndarray
    closed_loop: list = field(default_factory=list)
    open_loop: list = field(default_factory=list)
    braked: list = field(default_factory=list)
    closed_loop_eigenvalues: np.ndarray | None = None
    mode_index: np.ndarray | None = None
    linear: LinearModel | None = None
    equilibrium: Equilibrium | None = None

    @property
    def K_state(self) -> np.ndarray:
        return self.K[:-1]

    @property
    def K_integral(self) -> float:
        return float(self.K[-1])

    @property
    def closed_loop_matrix(self) -> np.ndarray:
        """A - B K of the augmented discrete model."""
        return self.A - self.B @ self.K[None, :]

    def spectral_radius(self) -> float:
        """Largest |z| of the closed-loop discrete matrix (< 1: stable)."""
        return float(np.max(np.abs(np.linalg.eigvals(self.closed_loop_matrix))))

    def riccati_residual(self) -> float:
        """Relative residual of the solved DARE (see :func:`riccati_residual`)."""
        i = self.index
        return riccati_residual(self.A[np.ix_(i, i)], self.B[i], self.Q, self.R, self.P)

    def command(self, dx: np.ndarray, z: float = 0.0) -> float:
        """Unclipped set-point [m/s] for the state deviation ``dx`` and integral ``z``."""
        return float(-(self.K_state @ dx) - self.K_integral * z)

    def mode(self, label: str, loop: str = "closed") -> Mode | None:
        """The mode named ``label`` in the "closed", "open" or "braked" loop list."""
        modes = {"closed": self.closed_loop, "open": self.open_loop, "braked": self.braked}[loop]
        return next((m for m in modes if m.label == label), None)

    def summary(self) -> dict:
        """{label: {"open": {"zeta", "period_s"}, "closed": {...}}} for :data:`NAMED_MODES`."""
        out = {}
        for label in NAMED_MODES:
            row = {}
            for loop in ("open", "closed"):
                m = self.mode(label, loop)
                row[loop] = ({"zeta": m.zeta, "period_s": m.period} if m is not None
                             else {"zeta": math.nan, "period_s": math.nan})
            out[label] = row
        return out


def design_lqr(params: Params, wind_speed: float, dt: float = 0.2, weights: dict | None = None,
               *, equilibrium: Equilibrium | None = None, subset: str = "auto") -> LQRDesign:
    """Discrete LQR with length integral action at mean wind speed ``wind_speed`` [m/s].

    Parameters
    ----------
    params : Params
        The aerostat, tether and winch.
    wind_speed : float
        Trim wind speed [m/s].
    dt : float
        Control step [s] (zero-order hold).
    weights : dict, optional
        Overrides of :data:`LQR_MAX_DEVIATIONS` (maximum acceptable deviations).
    equilibrium : Equilibrium, optional
        A trim at ``wind_speed`` to reuse (default: computed).
    subset : str
        "auto" (full model, longitudinal + winch subset if the full DARE fails), "full" or
        "long".

    Raises
    ------
    LQRDesignError if the DARE has no stabilizing solution or the loop is not stable.
    """
    if subset not in ("auto", "full", "long"):
        raise ValueError(f"subset must be 'auto', 'full' or 'long', got {subset!r}")
    if not (math.isfinite(dt) and dt > 0):
        raise ValueError(f"dt must be finite and > 0, got {dt!r}")
    w = _weights(params, weights)
    eq = equilibrium or find_equilibrium(params, float(wind_speed))
    lin = linearize(params, eq)
    lay = lin.layout
    Ad, Bd = discretize(lin.A_free, lin.B, dt)
    Aa, Ba = augment(Ad, Bd, lay, dt)
    Qf, R = bryson_weights(lay, w)
    nz = lay.size  # index of the integral state
    long_w = np.concatenate([lay.longitudinal_indices(), [lay.winch_length, lay.winch_speed]])
    subsets = {"full": np.arange(nz + 1), "long": np.concatenate([long_w, [nz]])}
    tries = ["full", "long"] if subset == "auto" else [subset]
    errors = []
    for name in tries:
        idx = subsets[name]
        A_s, B_s, Q_s = Aa[np.ix_(idx, idx)], Ba[idx], Qf[np.ix_(idx, idx)]
        try:
            P, K_s = dare_gain(A_s, B_s, Q_s, R)
        except (np.linalg.LinAlgError, ValueError) as exc:
            errors.append(f"{name}: {exc}")
            continue
        rho = float(np.max(np.abs(np.linalg.eigvals(A_s - B_s @ K_s))))
        if not (np.all(np.isfinite(K_s)) and rho < 1.0):
            errors.append(f"{name}: closed-loop spectral radius {rho:.6f} >= 1")
            continue
        break
    else:
        raise LQRDesignError(f"no stabilizing LQR at U = {wind_speed} m/s: {'; '.join(errors)}")
    K = np.zeros(nz + 1)
    K[idx] = K_s[0]
    design = LQRDesign(K=K, x_trim=np.asarray(eq.x, float).copy(), wind_speed=float(wind_speed),
                       dt=float(dt), weights=w, subset=name, A=Aa, B=Ba, Q=Q_s, R=R, P=P,
                       index=idx, linear=lin, equilibrium=eq)
    _fill_modes(design, params, lin, long_w, nz)
    return design


def _fill_modes(design: LQRDesign, params: Params, lin: LinearModel, long_w: np.ndarray,
                nz: int) -> None:
    """Closed-loop, open-loop (free winch) and braked longitudinal modes, named."""
    ctx = mode_context(params, design.x_trim, "long")
    braked = modal_table(decouple(lin.A, lin.layout).A_long, ctx)
    idx = np.concatenate([long_w, [nz]])
    Acl = design.closed_loop_matrix[np.ix_(idx, idx)]
    z, V = np.linalg.eig(Acl)
    s = np.log(z.astype(complex)) / design.dt
    design.closed_loop_eigenvalues = np.log(
        np.linalg.eigvals(design.closed_loop_matrix).astype(complex)) / design.dt
    closed = modes_from_eig(s, V, ctx)
    lam, W = np.linalg.eig(lin.A_free[np.ix_(long_w, long_w)])
    opened = modes_from_eig(lam, W, ctx)
    for modes in (closed, opened):
        _name_modes(modes, braked, ctx)
    design.closed_loop, design.open_loop, design.braked = closed, opened, braked
    design.mode_index = idx


def mode_initial_state(design: LQRDesign, label: str = "pendulum", amplitude: float = 0.5,
                       coordinate: str = "x_cm") -> tuple[np.ndarray, float]:
    """(dx, z0): a small initial deviation along one closed-loop mode.

    The mode's eigenvector is scaled so that ``coordinate`` (a name of
    :meth:`StateLayout.names`) starts at ``amplitude`` with zero phase; the real part is taken,
    so every tether node, velocity, the winch states and the integral move consistently and the
    linear response is the single damped oscillation amplitude e^{sigma t} cos(omega_d t) in that
    coordinate. dx has the full layout (6n+8, lateral entries 0); z0 is the integral state.
    """
    m = design.mode(label)
    if m is None:
        raise ValueError(f"no closed-loop mode named {label!r}")
    lay = design.linear.layout
    full = np.zeros(lay.size + 1, dtype=complex)
    full[design.mode_index] = m.vector
    c = full[lay.names().index(coordinate)]
    if abs(c) == 0:
        raise ValueError(f"mode {label!r} does not move {coordinate!r}")
    x = np.real(full * (amplitude / c))
    return x[:-1], float(x[-1])


# --- schedule -------------------------------------------------------------------------------------



class LQRSchedule:
    """Table of LQR designs over mean wind speed; gains interpolated linearly in U.

    Parameters
    ----------
    params : Params. speeds : design wind speeds [m/s], increasing (default
    :data:`DEFAULT_SPEEDS`, 2 to 16 m/s in 1 m/s steps). dt : control step [s].
    weights : overrides of :data:`LQR_MAX_DEVIATIONS`. subset : see :func:`design_lqr`.

    Attributes
    ----------
    speeds : (S,), the design speeds whose trim the winch motor holds (:func:`held_trims`).
    gains : (S, 6n+9). trims : (S, 6n+8). dt, weights, subset : design settings
    (``subsets`` per speed). pendulum_zeta, pitch_zeta : (S, 2) open/closed-loop predictions.
    build_time_s : wall time of the build (0 for a loaded table). designs : the
    :class:`LQRDesign` objects (only for a table built in this process).
    """

    def __init__(self, params: Params, speeds=None, dt: float = 0.2,
                 weights: dict | None = None, *, subset: str = "auto"):
        designs = self._build(params, speeds, dt, lambda U, eq: design_lqr(
            params, U, dt, weights, equilibrium=eq, subset=subset))
        self.weights = designs[0].weights
        self.subsets = [d.subset for d in designs]

    def _build(self, params: Params, speeds, dt: float, design_at) -> list:
        """Design at every speed (``design_at(U, equilibrium)``, trims by continuation in U)
        and fill the tables; returns the designs. Subclasses with another design rule (the
        modal controller) reuse it."""
        t0 = time.perf_counter()
        held = held_trims(params, DEFAULT_SPEEDS if speeds is None else speeds)
        designs = [design_at(U, eq) for U, eq in held]
        self.build_time_s = time.perf_counter() - t0
        self.params = params
        self.fingerprint = params_fingerprint(params)
        self.speeds = np.array([U for U, _ in held])
        self.dt = float(dt)
        self.gains = np.array([d.K for d in designs])
        self.trims = np.array([d.x_trim for d in designs])
        self.pendulum_zeta = np.array([[d.summary()["pendulum"][k]["zeta"] for k in ("open", "closed")]
                                       for d in designs])
        self.pitch_zeta = np.array([[d.summary()["pitching"][k]["zeta"] for k in ("open", "closed")]
                                    for d in designs])
        self.designs = designs
        return designs

    # --- lookup -----------------------------------------------------------------------------

    def gain(self, U) -> np.ndarray:
        """K at wind speed U (scalar: (6n+9,); array (N,): (N, 6n+9)); linear in U, clamped to
        the table's end speeds, and faded below its lowest speed (:func:`scheduled_tables`)."""
        U = np.asarray(U, float)
        if not np.all(np.isfinite(U)):
            raise ValueError(f"wind speed must be finite, got {U!r}")
        return scheduled_tables(self.speeds, {"K": self.gains}, U, {"K"})["K"]

    # --- persistence ------------------------------------------------------------------------

    def save(self, path: str | Path) -> Path:
        """Write the table to a .npz file (gains, trims, speeds, settings, params fingerprint)."""
        path = Path(path)
        np.savez(path, speeds=self.speeds, gains=self.gains, trims=self.trims,
                 dt=np.array(self.dt), pendulum_zeta=self.pendulum_zeta,
                 pitch_zeta=self.pitch_zeta,
                 meta=np.array(json.dumps({"weights": self.weights, "subsets": self.subsets,
                                           "fingerprint": self.fingerprint,
                                           "build_time_s": self.build_time_s})))
        return path if path.suffix == ".npz" else path.with_name(path.name + ".npz")

    @classmethod
    def load(cls, path: str | Path, params: Params | None = None) -> LQRSchedule:
        """Read a table written by :meth:`save`. With ``params``, check that the table was built
        for the same parameter set (ValueError otherwise)."""
        with np.load(Path(path), allow_pickle=False) as f:
            data = {k: f[k] for k in f.files}
        meta = json.loads(str(data["meta"]))
        if params is not None and params_fingerprint(params) != meta["fingerprint"]:
            raise ValueError(f"LQR schedule {path} was built for other parameters (fingerprint "
                             f"{meta['fingerprint'][:12]}, these are "
                             f"{params_fingerprint(params)[:12]}); rebuild it")
        self = cls.__new__(cls)
        self.params = params
        self.fingerprint = meta["fingerprint"]
        self.speeds = data["speeds"]
        self.gains = data["gains"]
        self.trims = data["trims"]
        self.dt = float(data["dt"])
        self.pendulum_zeta = data["pendulum_zeta"]
        self.pitch_zeta = data["pitch_zeta"]
        self.weights = meta["weights"]
        self.subsets = meta["subsets"]
        self.build_time_s = 0.0
        self.designs = None
        return self


# --- policy ---------------------------------------------------------------------------------------


class LQRPolicy:
    """Gain-scheduled LQR as an SB3-style policy over the environment's full observation.

    Parameters
    ----------
    params : Params
        Parameters of the environment.
    dt : float
        Control step [s] (must match the schedule's).
    schedule : LQRSchedule, optional
        The gain table (default: built here, a few seconds, over ``wind_range``).
    wind_range : (float, float), optional
        Wind speeds [m/s] the schedule must cover (default: :data:`DEFAULT_SPEEDS`, for the
        environment's default 3-15 m/s); see :func:`schedule_speeds`.
    privileged : bool
        True (the only mode implemented): the policy reads the exact state deviation and the
        episode's mean wind speed from the ``observation="full"`` vector.

    Notes
    -----
    Observation (``observation="full"``): index ``OBS_FULL_WIND`` holds U, the 6n+8 entries
    from ``OBS_FULL_STATE`` hold x - x_trim. The deviation is read in the swing plane
    (:mod:`aerostat_gym.agents.swing_plane`, about the schedule's trim at U) when
    :attr:`swing_plane` is set, so that a lateral swing's second-order dip in x and z does not
    drive the longitudinal loop. The set-point is v = -K(U) [dx; z], clipped to +-max_speed,
    and the action is v / max_speed. The integral z (one per environment) travels in ``state``: z <- z + dt dL,
    except while the command is saturated and integrating would push it further into
    saturation (conditional-integration anti-windup); ``episode_start`` resets it to 0.
    """

    #: Read the longitudinal state in the swing plane (see the notes above).
    swing_plane = True

    def __init__(self, params: Params, dt: float = 0.2, schedule: LQRSchedule | None = None,
                 privileged: bool = True, wind_range: tuple[float, float] | None = None):
        if not privileged:
            raise NotImplementedError("LQRPolicy needs the privileged full-state observation "
                                      "(privileged=True); output feedback is not implemented")
        self.params = params
        self.dt = float(dt)
        if schedule is None:
            speeds = None if wind_range is None else schedule_speeds(wind_range)
            schedule = LQRSchedule(params, speeds=speeds, dt=dt)
        self.schedule = schedule
        if abs(self.schedule.dt - self.dt) > 1e-12:
            raise ValueError(f"schedule was designed for dt = {self.schedule.dt} s, policy "
                             f"dt = {self.dt} s")
        self.layout = StateLayout(params.tether.n_elements)
        if self.schedule.gains.shape[1] != self.layout.size + 1:
            raise ValueError(f"schedule gains have {self.schedule.gains.shape[1]} columns, "
                             f"expected {self.layout.size + 1} for n = {self.layout.n_elements}")
        self.max_speed = float(params.winch.max_speed)
        self.obs_size = OBS_FULL_STATE + self.layout.size

    def predict(self, observation, state=None, episode_start=None, deterministic: bool = True):
        """(actions, state): actions (1,) for one observation or (N, 1) for a batch, float32 in
        [-1, 1]; state is the (N,) array of integral states to pass back next step."""
        obs2, single = as_batch(observation, float, episode_start)
        check_state_passed(self, state, episode_start, len(obs2), "the length integral")
        if obs2.ndim != 2 or obs2.shape[1] < self.obs_size:
            raise ValueError(
                f"LQRPolicy needs the full-state observation of length {self.obs_size} "
                f"(20 + 6n+8 with n = {self.layout.n_elements}), got shape {np.shape(observation)}; make the "
                f"environment with observation='full'")
        N = obs2.shape[0]
        z = np.zeros(N) if state is None else np.array(state, dtype=float).reshape(-1).copy()
        if z.shape != (N,):
            raise ValueError(f"state must hold one integral per environment, shape ({N},), got "
                             f"{np.shape(state)}")
        if episode_start is not None:
            z[np.asarray(episode_start, dtype=bool).reshape(-1)] = 0.0
        U = obs2[:, OBS_FULL_WIND]
        dx = obs2[:, OBS_FULL_STATE:OBS_FULL_STATE + self.layout.size].copy()
        ipsi = self.layout.at(S_PSI)
        dx[:, ipsi] = (dx[:, ipsi] + np.pi) % (2.0 * np.pi) - np.pi
        if self.swing_plane:
            sch = self.schedule
            x_ref = scheduled_tables(sch.speeds, {"x": sch.trims}, U)["x"]
            dx = in_swing_plane(dx, x_ref, self.layout)
        K = self.schedule.gain(U)
        v = -np.einsum("ij,ij->i", K[:, :-1], dx) - K[:, -1] * z
        v_cmd = np.clip(v, -self.max_speed, self.max_speed)
        dz = self.dt * dx[:, self.layout.winch_length]
        push = -K[:, -1] * dz  # change of v that integrating would cause
        wind_up = ((v >= self.max_speed) & (push > 0)) | ((v <= -self.max_speed) & (push < 0))
        z_next = np.where(wind_up, z, z + dz)
        actions = (v_cmd / self.max_speed).astype(np.float32)[:, None]
        actions = np.clip(actions, -1.0, 1.0)
        return (actions[0] if single else actions), z_next

    def predicted_modes(self, wind_speed: float) -> dict:
        """The linear model's open- and closed-loop pendulum, pitching and axial-spring modes of
        the design at the table speed nearest ``wind_speed`` (:meth:`LQRDesign.summary`)."""
        sch = self.schedule
        k = int(np.argmin(np.abs(sch.speeds - wind_speed)))
        out = {"design_wind_speed": float(sch.speeds[k])}
        if sch.designs is not None:
            return {**out, **sch.designs[k].summary()}
        # a schedule read from disk keeps the predicted damping ratios, not the designs
        for label, table in (("pendulum", sch.pendulum_zeta), ("pitching", sch.pitch_zeta)):
            out[label] = {loop: {"zeta": float(table[k, j]), "period_s": math.nan}
                          for j, loop in enumerate(("open", "closed"))}
        return out

    def reset(self) -> None:
        """Stateless between calls: the integral lives in ``state`` (kept for API symmetry)."""
