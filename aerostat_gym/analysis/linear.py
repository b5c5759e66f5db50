"""Linearization of the compiled model about a trim, and the [LN02] lateral/longitudinal split.

[LN02] (section "Linear Stability Analysis") forms the state matrix of X' = F(X) by finite
differences of the nonlinear right-hand side about a steady-wind equilibrium, with perturbations
of 1e-5. Here the same compiled :func:`aerostat_gym.physics.core.rhs` that the simulator
integrates is differentiated, so the linear model can never drift from the nonlinear one.

Two operating modes of the winch give two linear models:

* braked (u = [0, 1], the paper's case): the winch states L, v_w have zero derivatives and are
  left out, so ``A`` is the (6 n + 6) square matrix of the mechanical states (66 for n = 10);
* brake released, speed loop holding v_set = 0 (u = [0, 0]): ``A_free`` over all 6 n + 8 states
  and ``B``, one column per continuous actuator in :data:`ACTUATORS`. A new actuator (a fin
  flap, a thrust vector) plugs in by adding its input channel to the compiled core and one
  :class:`Actuator` entry here; nothing else changes.

python-control idioms: :meth:`LinearModel.ss` returns a ``control.StateSpace`` with named states
and inputs; ``control`` is imported only there.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..params import Params
from ..physics.state import N_INPUTS, U_BRAKE, U_SPEED, StateLayout
from ..sim import Model
from .trim import Equilibrium


@dataclass(frozen=True)
class Actuator:
    """One continuous input channel of the compiled core.

    Attributes
    ----------
    name : input name in the state-space model. index : position in the input vector u.
    unit : unit of the input. scale : typical magnitude; the finite-difference step is
    ``eps * scale``. description : one line for reports.
    """

    name: str
    index: int
    unit: str
    scale: float
    description: str


#: Continuous actuators of the model (the brake flag is a discrete switch and is not one).
ACTUATORS: tuple[Actuator, ...] = (
    Actuator("v_set", U_SPEED, "m/s", 1.0, "winch reel-out speed set-point (brake released)"),
)

#: Input at which the free-winch model is linearized: speed loop on, holding zero reel speed.
U_FREE = np.zeros(N_INPUTS)
#: Input of the paper's analysis: brake on.
U_BRAKED = np.zeros(N_INPUTS)
U_BRAKED[U_BRAKE] = 1.0


@dataclass
class LinearModel:
    """Linear model dx/dt = A dx (braked) or A_free dx + B du (brake released) about a trim.

    Attributes
    ----------
    A : (6n+6, 6n+6) state matrix of the mechanical states, winch braked ([LN02]'s matrix).
    A_free : (6n+8, 6n+8) state matrix with the brake released (speed loop at v_set = 0).
    B : (6n+8, m) input matrix for :attr:`actuators`, brake released.
    x_eq : trimmed state (6n+8). u_eq : input of ``A_free`` and ``B``.
    wind_speed : trim wind speed [m/s]. layout : state layout. eps : relative step used.
    steps : finite-difference step of every state [state units].
    """

    A: np.ndarray
    A_free: np.ndarray
    B: np.ndarray
    x_eq: np.ndarray
    u_eq: np.ndarray
    wind_speed: float
    layout: StateLayout
    eps: float
    steps: np.ndarray
    actuators: tuple = field(default=ACTUATORS)

    @property
    def state_names(self) -> list[str]:
        return self.layout.names()

    @property
    def input_names(self) -> list[str]:
        return [a.name for a in self.actuators]

    def ss(self, winch: bool = False):
        """``control.StateSpace`` with full-state output.

        winch=False: (A, 0, I, 0) over the mechanical states, braked (the paper's system; B has
        no column because a braked winch takes no input). winch=True: (A_free, B, I, 0) over
        all states, with one input per actuator.
        """
        import control

        names = self.state_names
        if winch:
            n = self.A_free.shape[0]
            return control.ss(self.A_free, self.B, np.eye(n), np.zeros((n, self.B.shape[1])),
                              states=names, inputs=self.input_names, outputs=names)
        n = self.A.shape[0]
        return control.ss(self.A, np.zeros((n, 1)), np.eye(n), np.zeros((n, 1)),
                          states=names[:n], inputs=["none"], outputs=names[:n])


def state_steps(x: np.ndarray, eps: float) -> np.ndarray:
    """Finite-difference step of every state, scaled to the state's magnitude.

    Notes
    -----
    h_i = eps * max(|x_i|, 1) in the state's SI unit (m, m/s, rad, rad/s). For eps = 1e-5, as
    in [LN02], a node 300 m up moves by 3 mm (a strain change of 1e-4 on a 30 m element, well
    inside the linear range) and every velocity, angle and rate by 1e-5.
    """
    return eps * np.maximum(np.abs(x), 1.0)


def central_jacobian(f, x: np.ndarray, cols: np.ndarray, steps: np.ndarray) -> np.ndarray:
    """Columns d f / d x_j for j in ``cols`` by central differences.

    Notes
    -----
    d f / d x_j ~ (f(x + h_j e_j) - f(x - h_j e_j)) / (2 h_j), truncation error O(h_j^2 f''').
    """
    cols = np.asarray(cols)
    J = np.empty((x.size, cols.size))
    for k, j in enumerate(cols):
        xp, xm = x.copy(), x.copy()
        xp[j] += steps[j]
        xm[j] -= steps[j]
        J[:, k] = (f(xp) - f(xm)) / (2.0 * steps[j])
    return J


#: Difference schemes of :func:`input_jacobian`: +1 forward, 0 central, -1 backward.
FORWARD, CENTRAL, BACKWARD = 1, 0, -1


def speed_difference_side(params: Params, length: float, h: float) -> int:
    """Which one-sided difference the reel-speed set-point needs at tether length ``length``.

    Notes
    -----
    The compiled winch caps the set-point near the length limits by the stopping profile
    v_cap(d) = min(d / (4 tau), sqrt(a_max d)), d the distance to the limit. A set-point step h
    crosses the cap when v_cap(d) < h, i.e. within d < max(4 tau h, h^2 / a_max) of a limit;
    there a central difference straddles the clip and halves B[v_w] (exactly at the limit the
    outward step is clipped to 0). The inward one-sided difference keeps B[v_w] = 1 / tau:
    backward (reel-in) near the upper limit, forward (reel-out) near the lower one.
    """
    w = params.winch
    reach = 2.0 * max(4.0 * w.speed_time_constant * h, h * h / w.max_acceleration)
    if w.max_length - length <= reach:
        return BACKWARD
    if length - w.min_length <= reach:
        return FORWARD
    return CENTRAL


def input_jacobian(model: Model, x: np.ndarray, u_eq: np.ndarray, actuators, eps: float) -> np.ndarray:
    """Input matrix B = d f / d u at (x, u_eq), one column per actuator.

    Central differences, except for the reel-speed set-point near the winch's length limits,
    where the inward one-sided difference avoids the set-point cap
    (:func:`speed_difference_side`).
    """
    B = np.empty((x.size, len(actuators)))
    length = float(x[model.layout.winch_length])
    for k, a in enumerate(actuators):
        h = eps * a.scale
        side = speed_difference_side(model.params, length, h) if a.index == U_SPEED else CENTRAL
        up, um = u_eq.copy(), u_eq.copy()
        up[a.index] += h * (side != BACKWARD)
        um[a.index] -= h * (side != FORWARD)
        B[:, k] = (model.rhs(x, up) - model.rhs(x, um)) / (up[a.index] - um[a.index])
    return B


def linearize(params: Params | None, equilibrium: Equilibrium, eps: float = 1e-5,
              actuators: tuple = ACTUATORS) -> LinearModel:
    """Linearize the compiled right-hand side about a trim by central finite differences.

    Parameters
    ----------
    params : parameters (default: ``equilibrium.params``).
    equilibrium : trim from :func:`aerostat_gym.analysis.trim.find_equilibrium`.
    eps : relative perturbation (see :func:`state_steps`); [LN02] used 1e-5.
    actuators : continuous inputs to differentiate (default :data:`ACTUATORS`).

    Returns
    -------
    LinearModel with A (braked, mechanical states), A_free and B (brake released).

    Notes
    -----
    A_ij = (F_i(X0 + h_j e_j) - F_i(X0 - h_j e_j)) / (2 h_j), B_ik likewise in u_k. The braked
    A is the mechanical block of the full Jacobian at u = [0, 1]: with the brake on, L and v_w
    have zero derivatives and L (the paid-out length) is a parameter, not a degree of freedom.
    """
    params = params or equilibrium.params
    model = Model(params, wind=equilibrium.wind_speed)
    x0 = np.asarray(equilibrium.x, float)
    lay = model.layout
    steps = state_steps(x0, eps)
    mech = np.arange(lay.n_mechanical)
    A_br = central_jacobian(lambda x: model.rhs(x, U_BRAKED), x0, mech, steps)
    A = A_br[mech]
    A_free = central_jacobian(lambda x: model.rhs(x, U_FREE), x0, np.arange(lay.size), steps)
    B = input_jacobian(model, x0, U_FREE.copy(), actuators, eps)
    return LinearModel(A=A, A_free=A_free, B=B, x_eq=x0.copy(), u_eq=U_FREE.copy(),
                       wind_speed=float(equilibrium.wind_speed), layout=lay, eps=eps,
                       steps=steps, actuators=tuple(actuators))


# --- decoupling ---------------------------------------------------------------------------------


@dataclass
class Decoupled:
    """[LN02] reordering X~ = [X_long; X_lat], A~ = [[A_long, A_ul], [A_ll, A_lat]].

    Attributes
    ----------
    A_long : (4n+2) square. A_lat : (2n+4) square. A_ul : (4n+2, 2n+4) effect of lateral states
    on longitudinal derivatives (upper right). A_ll : (2n+4, 4n+2) the reverse (lower left).
    long_idx, lat_idx : indices into the mechanical state. long_names, lat_names : their names.
    max_entry : largest |A_ij|. ratios : norms of the coupling blocks over ``max_entry``.
    """

    A_long: np.ndarray
    A_lat: np.ndarray
    A_ul: np.ndarray
    A_ll: np.ndarray
    long_idx: np.ndarray
    lat_idx: np.ndarray
    long_names: list
    lat_names: list
    max_entry: float
    ratios: dict


def decouple(A: np.ndarray, layout: StateLayout) -> Decoupled:
    """Reorder A into the longitudinal and lateral sets and measure their coupling.

    Parameters
    ----------
    A : (6n+6) square state matrix (mechanical states, layout order).
    layout : the state layout (gives :meth:`StateLayout.longitudinal_indices` and
        :meth:`StateLayout.lateral_indices`).

    Returns
    -------
    Decoupled. ``ratios`` holds, for the upper-right (``ul``) and lower-left (``ll``) blocks,
    the largest entry and the Frobenius norm, both divided by max |A_ij|.

    Notes
    -----
    For an aerostat and tether symmetric about the body xz-plane, trimmed in that plane, a
    lateral perturbation changes longitudinal forces only at second order, and vice versa, so
    both blocks vanish up to finite-difference and rounding error. [LN02] found the lower-left
    block zero and the upper right at about 1e-4 / 1e4 = 1e-8 of the largest entry.
    """
    li, ti = layout.longitudinal_indices(), layout.lateral_indices()
    names = layout.names()
    amax = float(np.max(np.abs(A)))
    ul, ll = A[np.ix_(li, ti)], A[np.ix_(ti, li)]
    ratios = {
        "ul_max": float(np.max(np.abs(ul))) / amax, "ul_fro": float(np.linalg.norm(ul)) / amax,
        "ll_max": float(np.max(np.abs(ll))) / amax, "ll_fro": float(np.linalg.norm(ll)) / amax,
    }
    return Decoupled(A_long=A[np.ix_(li, li)], A_lat=A[np.ix_(ti, ti)], A_ul=ul, A_ll=ll,
                     long_idx=li, lat_idx=ti, long_names=[names[i] for i in li],
                     lat_names=[names[i] for i in ti], max_entry=amax, ratios=ratios)


def propagate(Phi: np.ndarray, dx0: np.ndarray, steps: int) -> np.ndarray:
    """States dx_0 ... dx_steps (rows) of the discrete linear map dx_{k+1} = Phi dx_k: a free
    response with Phi = expm(A dt) (exact for the LTI system at the sampling instants), or a
    sampled closed loop with Phi its closed-loop matrix."""
    out = np.empty((steps + 1, dx0.size))
    out[0] = dx0
    for k in range(steps):
        out[k + 1] = Phi @ out[k]
    return out
