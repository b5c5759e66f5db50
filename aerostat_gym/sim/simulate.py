"""Trajectories: :func:`simulate` integrates the model and returns the time histories with
named fields, reporting tether break, full slackness and numerical failure as events rather
than raising.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..params import Params
from ..physics.integrators import NONFINITE
from ..physics.state import N_INPUTS
from ..wind.field import check_covers
from .model import BRAKED, Model, SimulationError, check_finite, check_integrator
from .winch import WinchController


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
    winch_tension: np.ndarray  # tether tension at the winch end [N] (true value)
    length: np.ndarray
    reel_speed: np.ndarray
    status: str = "ok"
    events: list = field(default_factory=list)
    # winch outputs (aerostat_gym.winch): per sample
    load_cell: np.ndarray | None = None  # winch tension as the load cell reads it [N]
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
    params : Params or None
        Parameter set (None: the shipped baseline).
    x0 : ndarray
        Initial state (layout: :class:`aerostat_gym.physics.state.StateLayout`).
    duration : float
        Length of the run [s].
    wind : None, float or (wp, wf)
        See :class:`aerostat_gym.sim.Model`.
    integrator : str
        "rk4" (reference) or "semi-implicit".
    dt : float, optional
        Integration step [s]; default the RK4 stability step or ``simulation.semi_implicit_dt``.
    output_dt : float
        Sampling interval of the returned trajectory [s].
    u : array-like or callable, optional
        Winch input [v_set, brake] held constant, or a callable u(t, x) evaluated once per
        output interval; default braked.
    model : Model, optional
        A model to reuse (its parameters and wind take precedence over ``params``/``wind``).

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
        check_covers(model.wp, model.wf, n_out * output_dt)
    winch = WinchController(model.params, output_dt)  # the stand-still clock ticks per interval
    times, states, tens, ends = [0.0], [x.copy()], [model.tensions(x)], [model.end_tensions(x)]
    status, events, cmds = "ok", [], []
    for k in range(n_out):
        t = k * output_dt
        cmd = winch.command(_input(u, t, x), x, winch.load_cell(ends[-1][1]))
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
        top_tension=E[:, 0], winch_tension=E[:, 1], length=L,
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
