"""The simulator's model: a parameter set bound to the compiled core.

:class:`Model` owns the packed parameters, the state layout, the wind vectors and the work
array, and advances a control interval with the compiled interval advance
(:func:`aerostat_gym.physics.integrators.advance_interval`), the same function the
environment's compiled step calls. Outputs (node positions, element and end tensions) are read
from the core's work array.
"""

from __future__ import annotations

import math

import numpy as np

from ..params import Params, load_params
from ..physics.core import evaluate_tether
from ..physics.core import rhs as _rhs
from ..physics.integrators import INTEGRATORS, advance_interval, rk4_interval_step, scheme
from ..physics.outputs import confluence_tension, winch_tension
from ..physics.packing import P_FIXED, pack_params
from ..physics.state import StateLayout, tension_offset, work_size
from ..physics.wind import NO_FIELD, mean_wind

BRAKED = np.array([0.0, 1.0])


class SimulationError(ValueError):
    """Invalid simulation input (bad state, input, duration or option)."""


def check_integrator(name: str) -> str:
    if name not in INTEGRATORS:
        raise SimulationError(f"unknown integrator {name!r}; choose one of {INTEGRATORS}")
    return name


def check_finite(name: str, arr: np.ndarray) -> np.ndarray:
    arr = np.asarray(arr, dtype=float)
    if not np.all(np.isfinite(arr)):
        raise SimulationError(f"{name} contains non-finite values: {arr[~np.isfinite(arr)][:5]}")
    return arr


class Model:
    """A parameter set bound to the compiled core.

    Parameters
    ----------
    params : Params, optional (default: the shipped baseline)
    fixed_aerostat : bool
        Hold the aerostat still (tether-only runs with a fixed top end).
    wind : None, float, or (wp, wf)
        None takes ``params.wind``; a float is a uniform steady wind of that speed along the
        configured direction; a tuple is a packed wind vector and turbulence field as built
        by :func:`aerostat_gym.wind.build_wind`.
    """

    def __init__(self, params: Params | None = None, wind=None, fixed_aerostat: bool = False):
        self.params = params or load_params()
        self.p = pack_params(self.params)
        if fixed_aerostat:  # hold the aerostat (and so the confluence point) where it is
            self.p[P_FIXED] = 1.0
        self.n = self.params.tether.n_elements
        self.layout = StateLayout(self.n)
        self.set_wind(wind)
        self.work = np.zeros(work_size(self.n))

    def set_wind(self, wind) -> None:
        w = self.params.wind
        if wind is None:
            self.wp, self.wf = mean_wind(w), NO_FIELD
        elif isinstance(wind, tuple):
            self.wp, self.wf = np.asarray(wind[0], float), np.asarray(wind[1], float)
        else:
            speed = float(wind)
            if not math.isfinite(speed) or speed < 0:
                raise SimulationError(f"wind speed must be finite and >= 0, got {wind!r}")
            self.wp, self.wf = mean_wind(w, speed), NO_FIELD

    # --- evaluations of the compiled core --------------------------------------------------

    def rhs(self, x: np.ndarray, u: np.ndarray | None = None, t: float = 0.0) -> np.ndarray:
        """State derivative f(t, x, u); u defaults to the braked winch."""
        dx = np.empty_like(x, dtype=float)
        _rhs(t, np.asarray(x, float), BRAKED if u is None else np.asarray(u, float), self.p,
             self.wp, self.wf, dx, self.work)
        return dx

    def _forces(self, x: np.ndarray, t: float = 0.0) -> np.ndarray:
        evaluate_tether(t, np.asarray(x, float), self.p, self.wp, self.wf, self.work)
        return self.work

    def node_positions(self, x: np.ndarray) -> np.ndarray:
        """Positions of all n + 1 nodes, (n + 1, 3): confluence point first, anchor last."""
        w = self._forces(x)
        return w[: 3 * (self.n + 1)].reshape(self.n + 1, 3).copy()

    def tensions(self, x: np.ndarray, t: float = 0.0) -> np.ndarray:
        """Element tensions [N], top element first."""
        w = self._forces(x, t)
        T0 = tension_offset(self.n)
        return w[T0:T0 + self.n].copy()

    def end_tensions(self, x: np.ndarray, t: float = 0.0) -> tuple[float, float]:
        """Tether tension at the aerostat end and at the winch end [N].

        A lumped element carries the continuous tether's tension at its midpoint; the ends
        differ by the weight of half an element: the top end is the magnitude of the total
        force the tether applies at the confluence point (element 0 plus the half element lumped
        there), the bottom end |T e - (mu l_u / 2) g z_hat| of the last element.
        """
        w = self._forces(x, t)
        return float(confluence_tension(self.p, w)), float(winch_tension(x, self.p, w))


    def rk4_dt(self, length: float | None = None) -> float:
        """RK4 step at the given (default: configured) length: the tether's axial stability
        bound, capped at the aerostat's explicit step ``simulation.semi_implicit_dt`` (as the
        compiled interval advance takes it)."""
        d, sim = self.params.derived, self.params.simulation
        L = self.params.tether.length if length is None else length
        return rk4_interval_step(d.EA, d.mass_per_length, L / self.n, sim.rk4_safety, self.n,
                                 sim.semi_implicit_dt)

    # --- time stepping ---------------------------------------------------------------------

    def scheme(self, integrator: str = "rk4", dt: float | None = None) -> np.ndarray:
        """The compiled interval advance's scheme vector for this parameter set."""
        sim = self.params.simulation
        return scheme(check_integrator(integrator), sim.rk4_safety, sim.semi_implicit_dt, dt)

    def advance(self, x: np.ndarray, t: float, interval: float, u: np.ndarray,
                integrator: str = "rk4", dt: float | None = None) -> tuple[int, np.ndarray]:
        """Advance x (in place) over ``interval`` seconds with input u held.

        Returns (status, tension stats) of
        :func:`aerostat_gym.physics.integrators.advance_interval`, the function the
        environment's compiled step calls too. ``dt`` fixes the step [s]; by default the RK4
        stability step at the current length or ``simulation.semi_implicit_dt``.
        """
        stats = np.array([0.0, np.inf])
        status = advance_interval(x, t, interval, u, self.p, self.wp, self.wf, self.work,
                                  self.scheme(integrator, dt), stats)
        return status, stats


