"""Trajectories: :func:`simulate` integrates the model and returns the time histories with
named fields, reporting tether break, ground strike, full slackness and numerical failure as
events rather than raising. Each output interval ends as an environment's control step does
(:func:`aerostat_gym.sim.events.step_outcome`, a terminating one decided by
:func:`aerostat_gym.sim.resolve.resolve`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..params import Params
from ..physics.integrators import NONFINITE
from ..physics.state import N_INPUTS, S_Z
from ..wind.field import check_covers
from . import events as E
from .model import BRAKED, Model, SimulationError, check_finite, check_integrator
from .resolve import resolve
from .winch import WinchController

#: Trajectory.status of a run that an outcome ended (RUNNING: it ran to the end, "ok").
STATUS = {E.RUNNING: "ok", E.NONFINITE: "nonfinite", E.TETHER_BREAK: "break",
          E.GROUND_STRIKE: "ground_strike", E.LENGTH_LIMIT: "length_limit",
          E.DIVERGED: "diverged"}
#: Numerical failures: the run stops at the last good sample, the failed interval dropped.
_FAILED = (E.NONFINITE, E.DIVERGED)


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
    Trajectory. ``status`` is "ok", or what ended the run early, as it ends an environment's
    episode: "break" (an element exceeded the tether strength), "ground_strike" (the CM below
    one hull diameter), "length_limit" (the tether length outside the winch's limits), with
    the run kept up to and including that sample; or a numerical failure, "nonfinite" (the
    state became non-finite) or "diverged" (a finite state beyond every physical bound, or an
    event that finer integration steps show to be the integrator's), with the run stopped at
    the last good sample. A terminating interval is re-run with finer steps first, and a
    tension peak that only the coarse step saw ends nothing. Each ending is also the last
    entry of ``events``. A fully slack tether is recorded in ``events`` ("slack") and the run
    continues, as are the onsets of the winch events "winch_slack" (load cell below
    winch.slack_tension) and "over_tension" (an element above winch.safe_working_load).

    Notes
    -----
    The input passes once per output interval through :class:`aerostat_gym.winch.WinchController`
    (set-point clipping and counting, the brake rule, which may set v_w to 0 as the brake
    clamps), the same logic the environment uses per control step.
    """
    model = model or Model(params, wind)
    x, n_out = _checked_start(model, x0, duration, integrator, dt, output_dt)
    winch = WinchController(model.params, output_dt)  # the stand-still clock ticks per interval
    times, states, tens, ends = [0.0], [x.copy()], [model.tensions(x)], [model.end_tensions(x)]
    ground = E.ground_height(model.params)
    status, events, cmds = "ok", [], []
    for k in range(n_out):
        t = k * output_dt
        cmd = winch.command(_input(u, t, x), x, winch.load_cell(ends[-1][1]))
        code, stats = _interval(model, x, t, output_dt, cmd.as_input(), integrator, dt, ground)
        if code in _FAILED:
            status = STATUS[code]
            events.append(_failure_event(code, t + output_dt))
            break
        cmds.append(cmd)
        times.append(t + output_dt)
        states.append(x.copy())
        tens.append(model.tensions(x, t + output_dt))
        ends.append(model.end_tensions(x, t + output_dt))
        if stats[1] <= 0.0:
            events.append({"time": t + output_dt, "event": "slack",
                           "message": "every tether element was slack during this interval"})
        events.extend(winch.detect_events(t + output_dt, winch.load_cell(ends[-1][1]), stats[0]))
        if code != E.RUNNING:
            status = STATUS[code]
            if code != E.TETHER_BREAK:  # the winch's events already end with the break
                events.append(_ending_event(code, t + output_dt, x, model))
            break
    return _trajectory(model, winch, np.array(times), np.array(states), np.array(tens),
                       np.array(ends), cmds, status, events)


def _checked_start(model: Model, x0, duration: float, integrator: str, dt: float | None,
                   output_dt: float) -> tuple[np.ndarray, int]:
    """(a copy of x0, the number of output intervals), each argument checked at the door: a
    SimulationError naming it, never a failure mid-run."""
    check_integrator(integrator)
    lay = model.layout
    x = check_finite("x0", np.array(x0, dtype=float))
    if x.shape != (lay.size,):
        raise SimulationError(f"x0 must have shape ({lay.size},) for n = {model.n}, got {x.shape}")
    _check_length(model, x)
    if not (math.isfinite(duration) and duration > 0):
        raise SimulationError(f"duration must be finite and > 0, got {duration!r}")
    if not (math.isfinite(output_dt) and output_dt > 0):
        raise SimulationError(f"output_dt must be finite and > 0, got {output_dt!r}")
    if dt is not None and not (math.isfinite(dt) and dt > 0):
        raise SimulationError(f"dt must be finite and > 0, got {dt!r}")
    n_out = max(1, int(round(duration / output_dt)))
    if model.wf.shape[1] > 1:  # a turbulence field must cover the whole run (clear error if not)
        check_covers(model.wp, model.wf, n_out * output_dt)
    return x, n_out


def _trajectory(model: Model, winch: WinchController, times: np.ndarray, S: np.ndarray,
                tensions: np.ndarray, end_T: np.ndarray, cmds: list, status: str,
                events: list) -> Trajectory:
    """The recorded samples (states S, element and end tensions per sample, one winch command
    per interval) as a :class:`Trajectory`, with the quantities read from them."""
    lay = model.layout
    L = S[:, lay.winch_length]
    return Trajectory(
        time=times, states=S, cm_pos=S[:, lay.cm_pos], cm_vel=S[:, lay.cm_vel],
        euler=S[:, lay.euler], rates=S[:, lay.rates],
        node_pos=np.array([model.node_positions(s) for s in S]), tensions=tensions,
        top_tension=end_T[:, 0], winch_tension=end_T[:, 1], length=L,
        reel_speed=S[:, lay.winch_speed], status=status, events=events,
        load_cell=np.array([winch.load_cell(b) for b in end_T[:, 1]]),
        mass_aloft=winch.mass_aloft(L), mass_on_drum=winch.mass_on_drum(L),
        v_set_requested=np.array([c.requested for c in cmds]),
        v_set=np.array([c.v_set for c in cmds]), brake=np.array([c.brake for c in cmds], dtype=bool),
        clipped_count=sum(c.clipped for c in cmds), thresholds=winch.thresholds.as_dict(),
    )


def _check_length(model: Model, x: np.ndarray) -> None:
    """x0's tether length within the winch's limits (leaving them ends a run, as it ends an
    episode, so a start outside them would end the run at once)."""
    w, L = model.params.winch, float(x[model.layout.winch_length])
    if not w.min_length - E.LENGTH_TOL <= L <= w.max_length + E.LENGTH_TOL:
        raise SimulationError(
            f"x0's tether length {L:g} m is outside the winch's limits [{w.min_length:g}, "
            f"{w.max_length:g}] m (winch.min_length, winch.max_length): trim at a length "
            "within them, or widen them")


def _interval(model: Model, x: np.ndarray, t: float, interval: float, u: np.ndarray,
              integrator: str, dt: float | None, ground: float) -> tuple[int, np.ndarray]:
    """Advance x over one output interval and decide its outcome as an environment's control
    step does: (outcome code of :mod:`aerostat_gym.sim.events`, tension stats). x holds the
    state the run goes on from (re-integrated where a terminating step was re-run)."""
    x_prev = x.copy()
    status, stats = model.advance(x, t, interval, u, integrator, dt)
    if status == NONFINITE:
        return E.NONFINITE, stats
    code = E.step_outcome(x, t + interval, model.p, stats[0], ground, math.inf)
    if E.terminating(code):
        code = resolve(code, x, x_prev, t, interval, u, model.p, model.wp, model.wf,
                       model.work, model.scheme(integrator, dt), stats, ground, math.inf)
    return code, stats


def _failure_event(code: int, t: float) -> dict:
    text = ("state became non-finite" if code == E.NONFINITE else
            "the integration diverged (a state beyond every physical bound, or an event that "
            "finer integration steps do not reproduce)")
    return {"time": t, "event": STATUS[code], "message": f"{text} (numerical failure)"}


def _ending_event(code: int, t: float, x: np.ndarray, model: Model) -> dict:
    lay = model.layout
    if code == E.GROUND_STRIKE:
        text = (f"the aerostat's CM came down to {x[lay.at(S_Z)]:.2f} m, below one hull "
                f"diameter ({E.ground_height(model.params):g} m)")
    else:
        w = model.params.winch
        text = (f"the tether length {x[lay.winch_length]:.3f} m left the winch's limits "
                f"[{w.min_length:g}, {w.max_length:g}] m")
    return {"time": t, "event": STATUS[code], "message": text}


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
