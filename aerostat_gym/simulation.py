"""The simulator: owns time, the integrator choice and the wind state; calls the compiled core.

:class:`Model` binds a parameter set to the compiled right-hand side (packed parameters, state
layout, wind vectors, work array). :func:`simulate` integrates a trajectory and returns it with
named fields, reporting tether break, full slackness and numerical failure as events rather
than raising.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .params import Params, load_params
from .physics.core import evaluate_tether, work_size
from .physics.core import rhs as _rhs
from .physics.integrators import NONFINITE, rk4_advance, rk4_step, si_advance
from .physics.layout import N_INPUTS, StateLayout, pack_params
from .physics.outputs import confluence_tension, winch_end_tension
from .physics.wind import NO_FIELD, pack_wind, wind_from_params
from .winch import WinchController

INTEGRATORS = ("rk4", "semi-implicit")
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
            from .physics.layout import P_FIXED

            self.p[P_FIXED] = 1.0
        self.n = self.params.tether.n_elements
        self.layout = StateLayout(self.n)
        self.set_wind(wind)
        self.work = np.zeros(work_size(self.n))

    def set_wind(self, wind) -> None:
        w = self.params.wind
        if wind is None:
            self.wp, self.wf = wind_from_params(w), NO_FIELD
        elif isinstance(wind, tuple):
            self.wp, self.wf = np.asarray(wind[0], float), np.asarray(wind[1], float)
        else:
            speed = float(wind)
            if not math.isfinite(speed) or speed < 0:
                raise SimulationError(f"wind speed must be finite and >= 0, got {wind!r}")
            self.wp = pack_wind(w.profile, speed, w.direction_deg, w.reference_height,
                                w.shear_exponent, w.roughness_length)
            self.wf = NO_FIELD

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
        T0 = 9 * (self.n + 1)
        return w[T0:T0 + self.n].copy()

    def end_tensions(self, x: np.ndarray, t: float = 0.0) -> tuple[float, float]:
        """Tether tension at the aerostat end and at the winch end [N].

        A lumped element carries the continuous tether's tension at its midpoint; the ends
        differ by the weight of half an element: the top end is the magnitude of the total
        force the tether applies at the confluence point (element 0 plus the half element lumped
        there), the bottom end |T e - (mu l_u / 2) g z_hat| of the last element.
        """
        w = self._forces(x, t)
        return float(confluence_tension(self.p, w)), float(winch_end_tension(x, self.p, w))


    def rk4_dt(self, length: float | None = None) -> float:
        """RK4 step from the axial stability bound at the given (default: configured) length."""
        d = self.params.derived
        L = self.params.tether.length if length is None else length
        return rk4_step(d.EA, d.mass_per_length, L / self.n, self.params.simulation.rk4_safety, self.n)

    # --- time stepping ---------------------------------------------------------------------

    def advance(self, x: np.ndarray, t: float, interval: float, u: np.ndarray,
                integrator: str = "rk4", dt: float | None = None) -> tuple[int, np.ndarray]:
        """Advance x (in place) over ``interval`` seconds; returns (status, tension stats)."""
        if integrator == "rk4":
            h_max = dt or self.rk4_dt(x[self.layout.winch_length])
        else:
            h_max = dt or self.params.simulation.semi_implicit_dt
        nsteps = max(1, math.ceil(interval / h_max - 1e-9))
        h = interval / nsteps
        stats = np.array([0.0, np.inf])
        fn = rk4_advance if integrator == "rk4" else si_advance
        status = fn(x, t, h, nsteps, u, self.p, self.wp, self.wf, self.work, stats)
        return status, stats


@dataclass
class Trajectory:
    """A simulated trajectory sampled every ``output_dt`` (arrays over time, first axis)."""

    time: np.ndarray
    states: np.ndarray
    cm_pos: np.ndarray
    cm_vel: np.ndarray
    euler: np.ndarray
    rates: np.ndarray
    node_pos: np.ndarray
    tensions: np.ndarray
    top_tension: np.ndarray
    bottom_tension: np.ndarray
    length: np.ndarray
    reel_speed: np.ndarray
    status: str = "ok"
    events: list = field(default_factory=list)
    # winch outputs (aerostat_gym.winch): per sample
    load_cell: np.ndarray | None = None  # winch-end tension as measured [N]
    mass_aloft: np.ndarray | None = None  # tether mass paid out [kg]
    mass_on_drum: np.ndarray | None = None  # tether mass on the drum [kg]
    # per control interval k, held over [time[k], time[k+1]) (length len(time) - 1)
    v_set_requested: np.ndarray | None = None  # validated set-point [m/s]
    v_set: np.ndarray | None = None  # set-point applied by the core [m/s] (clipped, 0 braking)
    brake: np.ndarray | None = None  # brake holding the drum
    clipped_count: int = 0  # intervals whose set-point was clipped to +-max_speed
    thresholds: dict = field(default_factory=dict)  # event thresholds [N]

    @property
    def attitude(self) -> np.ndarray:
        return self.euler


def simulate(params: Params | None, x0: np.ndarray, duration: float, wind=None,
             integrator: str = "rk4", dt: float | None = None, output_dt: float = 0.1,
             u=None, model: Model | None = None) -> Trajectory:
    """Integrate the model from x0 for ``duration`` seconds.

    Parameters
    ----------
    params : Params or None (baseline). x0 : initial state (layout: :class:`StateLayout`).
    wind : see :class:`Model`. integrator : "rk4" (reference) or "semi-implicit".
    dt : integration step [s]; default the RK4 stability step or ``simulation.semi_implicit_dt``.
    output_dt : sampling interval of the returned trajectory [s].
    u : winch input [v_set, brake] held constant, or a callable u(t, x) evaluated once per
        output interval; default braked.

    Returns
    -------
    Trajectory. ``status`` is "ok", "break" (an element exceeded the tether strength; the run
    stops there), or "nonfinite" (numerical failure; the run stops at the last finite sample).
    A fully slack tether is recorded in ``events`` ("slack") and the run continues, as are the
    onsets of the winch events "winch_slack" (load cell below winch.slack_tension) and
    "over_tension" (an element above winch.safe_working_load).

    Notes
    -----
    The input passes once per output interval through :class:`aerostat_gym.winch.WinchController`
    (set-point clipping and counting, the brake rule, which may set v_w to 0 as the brake
    clamps), the same logic the environment uses per control step.
    """
    model = model or Model(params, wind)
    check_integrator(integrator)
    lay = model.layout
    x = check_finite("x0", np.array(x0, dtype=float))
    if x.shape != (lay.size,):
        raise SimulationError(f"x0 must have shape ({lay.size},) for n = {model.n}, got {x.shape}")
    if not (math.isfinite(duration) and duration > 0):
        raise SimulationError(f"duration must be finite and > 0, got {duration!r}")
    if not (math.isfinite(output_dt) and output_dt > 0):
        raise SimulationError(f"output_dt must be finite and > 0, got {output_dt!r}")
    if dt is not None and not (math.isfinite(dt) and dt > 0):
        raise SimulationError(f"dt must be finite and > 0, got {dt!r}")
    n_out = max(1, int(round(duration / output_dt)))
    if model.wf.shape[1] > 1:  # a turbulence field must cover the whole run (clear error if not)
        from .wind.field import check_covers

        check_covers(model.wp, model.wf, n_out * output_dt)
    winch = WinchController(model.params)
    times, states, tens, ends = [0.0], [x.copy()], [model.tensions(x)], [model.end_tensions(x)]
    status, events, cmds = "ok", [], []
    for k in range(n_out):
        t = k * output_dt
        cmd = winch.command(_input(u, t, x), x)
        st, stats = model.advance(x, t, output_dt, cmd.as_input(), integrator, dt)
        if st == NONFINITE:
            status = "nonfinite"
            events.append({"time": t + output_dt, "event": "nonfinite",
                           "message": "state became non-finite (numerical failure)"})
            break
        cmds.append(cmd)
        times.append(t + output_dt)
        states.append(x.copy())
        tens.append(model.tensions(x, t + output_dt))
        ends.append(model.end_tensions(x, t + output_dt))
        if stats[1] <= 0.0:
            events.append({"time": t + output_dt, "event": "slack",
                           "message": "every tether element was slack during this interval"})
        new = winch.detect_events(t + output_dt, winch.load_cell(ends[-1][1]), stats[0])
        events.extend(new)
        if any(e["event"] == "break" for e in new):
            status = "break"
            break
    S = np.array(states)
    nodes = np.array([model.node_positions(s) for s in S])
    E = np.array(ends)
    L = S[:, lay.winch_length]
    return Trajectory(
        time=np.array(times), states=S, cm_pos=S[:, lay.cm_pos], cm_vel=S[:, lay.cm_vel],
        euler=S[:, lay.euler], rates=S[:, lay.rates], node_pos=nodes, tensions=np.array(tens),
        top_tension=E[:, 0], bottom_tension=E[:, 1], length=L,
        reel_speed=S[:, lay.winch_speed], status=status, events=events,
        load_cell=np.array([winch.load_cell(b) for b in E[:, 1]]),
        mass_aloft=winch.mass_aloft(L), mass_on_drum=winch.mass_on_drum(L),
        v_set_requested=np.array([c.requested for c in cmds]),
        v_set=np.array([c.v_set for c in cmds]), brake=np.array([c.brake for c in cmds], dtype=bool),
        clipped_count=sum(c.clipped for c in cmds), thresholds=winch.thresholds.as_dict(),
    )


def _input(u, t: float, x: np.ndarray) -> np.ndarray:
    if u is None:
        return BRAKED
    val = u(t, x) if callable(u) else u
    arr = np.asarray(val, dtype=float).reshape(-1)
    if arr.shape != (N_INPUTS,):
        raise SimulationError(f"winch input must be [v_set, brake], got {val!r}")
    if not np.all(np.isfinite(arr)):
        raise SimulationError(f"winch input must be finite, got {val!r}")
    return arr
