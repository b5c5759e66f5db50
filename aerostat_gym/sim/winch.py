"""Ground winch: the logic that runs once per control step around the compiled speed loop.

The continuous dynamics (speed loop with first-order lag, acceleration and speed limits, the
drivetrain reflected to the line, the motor force limit, the length-limit stopping profile,
the brake that freezes the drum) live in the compiled right-hand side
(:func:`aerostat_gym.physics.core._winch`), whose input is ``u = [v_set, brake]``. This module
holds what a winch's supervisory controller does between control steps, so that
:func:`aerostat_gym.sim.simulate` and the Gymnasium environment share one copy:

- set-point validation: a NaN or infinite set-point is an error (:class:`WinchInputError`,
  naming the value); a set-point beyond +-max_speed is clipped and counted;
- the brake rule (:func:`brake_wanted`, :func:`brake_rule`): the brake is wanted when
  commanded, when the set-point is exactly 0, or when |v_set| has stayed below ``brake_speed``
  (the stand-still band) for ``brake_dwell`` seconds; it clamps the drum only once
  |v_w| <= ``brake_hold_speed`` (v_w is then set to exactly 0). Until then the speed loop
  decelerates the drum toward zero at its acceleration limit;
- the load cell (winch-end tether tension, noise-free for now);
- tether mass bookkeeping: mass aloft mu L, mass on the drum mu (total_line_length - L);
- events with their thresholds: ``winch_slack`` (load cell below ``slack_tension``),
  ``over_tension`` (peak element tension above ``safe_working_load``), ``break`` (peak element
  tension above the tether's ``strength``).

Typical use, once per control step of length ``dt_c``::

    winch = WinchController(params)
    cmd = winch.command(action, x)           # may set x[v_w] = 0 as the brake clamps
    status, stats = model.advance(x, t, dt_c, cmd.as_input())
    load = winch.load_cell(model.end_tensions(x)[1])
    events = winch.detect_events(t + dt_c, load, stats[0])

The reel-out/reel-in manoeuvre is :mod:`aerostat_gym.analysis.manoeuvre`; the winch's column
of the input matrix B is :func:`aerostat_gym.analysis.linear.input_jacobian`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from ..params import Params, load_params
from ..physics.core import winch_friction
from ..physics.state import StateLayout, tension_offset
from .events import tether_broken


class WinchInputError(ValueError):
    """An invalid winch command (non-finite set-point or brake flag, wrong shape)."""


@dataclass(frozen=True)
class WinchThresholds:
    """Tension thresholds of the winch events [N]."""

    slack_tension: float
    safe_working_load: float
    strength: float

    @classmethod
    def from_params(cls, params: Params) -> WinchThresholds:
        w = params.winch
        return cls(w.slack_tension, w.safe_working_load, params.tether.strength)

    def as_dict(self) -> dict:
        return {"slack_tension": self.slack_tension, "safe_working_load": self.safe_working_load,
                "strength": self.strength}


@dataclass(frozen=True)
class WinchCommand:
    """What the winch applies over one control step.

    requested : validated set-point [m/s] (before clipping). v_set : set-point sent to the
    compiled core [m/s] (clipped to +-max_speed; 0 while braking). brake : the brake holds the
    drum over this step. clipped : the requested set-point was beyond +-max_speed.
    clamped : the brake engaged at the start of this step and set v_w to 0.
    """

    requested: float
    v_set: float
    brake: bool
    clipped: bool
    clamped: bool

    def as_input(self) -> np.ndarray:
        """The compiled core's input u = [v_set, brake]."""
        return np.array([self.v_set, 1.0 if self.brake else 0.0])


def parse_command(u) -> tuple[float, bool]:
    """(set-point, brake flag) from a scalar set-point or a pair [v_set, brake].

    Raises :class:`WinchInputError` naming the value for a non-finite entry or a wrong shape.
    """
    arr = np.asarray(u, dtype=float).reshape(-1)
    if arr.size not in (1, 2):
        raise WinchInputError(f"winch command must be v_set or [v_set, brake], got {u!r}")
    v = float(arr[0])
    if not math.isfinite(v):
        raise WinchInputError(f"winch set-point must be finite, got v_set = {v!r}")
    brake = float(arr[1]) if arr.size == 2 else 0.0
    if not math.isfinite(brake):
        raise WinchInputError(f"winch brake flag must be finite, got brake = {brake!r}")
    return v, brake != 0.0


@njit(cache=True)
def brake_wanted(v, brake_cmd, quiet, dt, band, dwell):
    """The supervisory brake request of one control step; returns (wanted, quiet).

    Parameters
    ----------
    v : float
        Requested set-point [m/s].
    brake_cmd : bool
        The brake is commanded explicitly.
    quiet : float
        Time the set-point has stayed inside the stand-still band before this step [s].
    dt : float
        Control step [s].
    band : float
        Stand-still band: |v| below this counts as "stand still" [m/s] (``winch.brake_speed``).
    dwell : float
        Stand-still time after which the brake is applied [s] (``winch.brake_dwell``).

    Notes
    -----
    A real winch's parking brake is applied by its supervisory logic once the drive has been
    asked to stand still for a while, not at every small command. A linear controller's
    set-point passes through any band around zero twice per pendulum period and stays inside
    it for the whole tail of a small swing; braking there at once would swallow those
    commands. So the brake is wanted when it is commanded, when the set-point is exactly 0 (the
    environment's action 0, the passive braked winch), or when |v| has stayed below ``band``
    for at least ``dwell`` seconds (``quiet`` counts that time, including this step, and
    restarts at 0 whenever |v| >= band). With ``dwell = 0`` any set-point inside the band
    brakes at once (the dead-band rule of aerostat-gym 0.2).
    """
    quiet = quiet + dt if abs(v) < band else 0.0
    want = brake_cmd or v == 0.0 or (abs(v) < band and quiet >= dwell - 1e-9)
    return want, quiet


@njit(cache=True)
def brake_rule(v, want, braked, v_w, max_speed, hold_speed, tension=0.0, max_force=np.inf):
    """One control step of the winch's brake and set-point logic; returns (v_set, brake, v_w).

    Parameters
    ----------
    v : float
        Requested reel-out speed [m/s].
    want : bool
        The brake is wanted (:func:`brake_wanted`).
    braked : bool
        The brake held the drum over the last step.
    v_w : float
        Drum (reel-out) speed at the start of the step [m/s].
    max_speed : float
        Rated drum speed [m/s].
    hold_speed : float
        The brake clamps the drum once it is this slow [m/s].
    tension : float
        Load-cell tension at the start of the step [N].
    max_force : float
        The motor's force limit at the line [N].

    Notes
    -----
    Wanted, the brake clamps the drum (v_w set to exactly 0) if it already held it or once
    |v_w| <= hold_speed; until then the speed loop decelerates the drum with set-point 0.
    Released, the set-point is clipped to +-max_speed.

    Over-hauled (the line tension above the motor's force limit, so the motor cannot hold the
    load), a ground winch does not let the load run the drum out against a reel-in or hold
    command: its holding brake sets at once, whatever the drum speed, and stays set while the
    load exceeds the motor force (the drive releases the brake only onto a load it can hold).
    The brake's holding rating is taken at or above the tether strength, so it holds until
    the tether breaks. A pay-out command is obeyed, at no more than the rated drum speed (the
    overspeed brake in :func:`aerostat_gym.physics.core._winch`). A drum speed above the rating
    (a step that ended over-hauled) is brought back to it here.
    Compiled so the environment's compiled step applies the same rule.
    """
    v_w = min(max(v_w, -max_speed), max_speed)
    if tension > max_force and (want or v <= 0.0):
        return 0.0, True, 0.0
    if want:
        if braked or abs(v_w) <= hold_speed:
            return 0.0, True, 0.0
        return 0.0, False, v_w
    return min(max(v, -max_speed), max_speed), False, v_w


class WinchController:
    """Per-control-step winch logic (see the module docstring). One instance per episode.

    Parameters
    ----------
    params : Params (default: the shipped baseline).

    Attributes
    ----------
    n_steps, n_clipped : control steps taken and steps whose set-point was clipped.
    braked : whether the brake holds the drum (after the last :meth:`command`).
    quiet : time the set-point has stayed inside the stand-still band [s].
    dt : control step [s] (the stand-still clock's tick).
    thresholds : :class:`WinchThresholds`.
    """

    def __init__(self, params: Params | None = None, dt: float = 0.2):
        self.params = params or load_params()
        if not (isinstance(dt, (int, float)) and math.isfinite(dt) and dt > 0):
            raise ValueError(f"winch control step dt must be a finite number > 0, got {dt!r}")
        self.dt = float(dt)  # total_line_length >= max_length checked at load
        self.layout = StateLayout(self.params.tether.n_elements)
        self.mu = self.params.derived.mass_per_length
        self.thresholds = WinchThresholds.from_params(self.params)
        self.reset()

    def reset(self) -> None:
        self.n_steps = 0
        self.n_clipped = 0
        self.braked = False
        self.quiet = 0.0
        self._slack = False
        self._over = False

    # --- command -------------------------------------------------------------------------------

    def command(self, u, x: np.ndarray, tension: float = 0.0) -> WinchCommand:
        """Validate and apply one command ``u`` (v_set or [v_set, brake]) at state ``x``, with
        the load-cell ``tension`` [N] of that state (over-haul hold, see :func:`brake_rule`).

        Brake rule (:func:`brake_wanted`): wanted when commanded, on an exact-zero set-point,
        or once |v_set| has stayed below brake_speed for brake_dwell seconds. If the drum is slow
        enough (|v_w| <= brake_hold_speed) the brake clamps: ``x[v_w]`` is set to exactly 0 (in
        place) and the core holds L fixed. Otherwise the speed loop decelerates the drum with
        set-point 0 and the brake is tried again at the next step. Released, the set-point is
        clipped to +-max_speed (counted in :attr:`n_clipped`).
        """
        w = self.params.winch
        v, brake_cmd = parse_command(u)
        clipped = abs(v) > w.max_speed and not brake_cmd  # a commanded brake ignores v_set
        self.n_steps += 1
        self.n_clipped += int(clipped)
        iv = self.layout.winch_speed
        want, self.quiet = brake_wanted(v, brake_cmd, self.quiet, self.dt, w.brake_speed,
                                        w.brake_dwell)
        v_set, brake, v_w = brake_rule(v, want, self.braked, x[iv], w.max_speed,
                                       w.brake_hold_speed, float(tension), w.max_motor_force)
        clamped = brake and not self.braked
        x[iv] = v_w  # exactly 0 once the brake holds the drum
        self.braked = brake
        return WinchCommand(v, v_set, brake, clipped, clamped)

    # --- measurements and bookkeeping ----------------------------------------------------------

    def load_cell(self, winch_tension: float) -> float:
        """Load-cell reading [N]: the tether tension at the winch end (noise-free)."""
        return float(winch_tension)

    @property
    def total_mass(self) -> float:
        """Tether mass on the winch, aloft plus on the drum [kg] (constant)."""
        return self.mu * self.params.winch.total_line_length

    def mass_aloft(self, length):
        """Tether mass paid out [kg]: mu L (the lumped model carries exactly this mass)."""
        return self.mu * np.asarray(length, dtype=float)

    def mass_on_drum(self, length):
        """Tether mass still on the drum [kg]: mu (total_line_length - L)."""
        return self.mu * (self.params.winch.total_line_length - np.asarray(length, dtype=float))

    # --- events --------------------------------------------------------------------------------

    def detect_events(self, t: float, load_cell: float, peak_tension: float) -> list[dict]:
        """Events at the end of a control step (onsets only for slack and over-tension).

        load_cell : the winch-end tension at time t [N]. peak_tension : the largest element
        tension over the step [N] (``stats[0]`` of :meth:`aerostat_gym.sim.Model.advance`).
        Returns a list of ``{"time", "event", "message", "value", "threshold"}`` dicts:
        ``winch_slack`` (load cell falls below slack_tension), ``over_tension`` (peak rises above
        safe_working_load), ``break`` (peak above the tether strength; every step it holds).
        """
        th, out = self.thresholds, []
        slack = load_cell < th.slack_tension
        if slack and not self._slack:
            out.append(_event(t, "winch_slack", load_cell, th.slack_tension,
                              f"winch tension {load_cell:.0f} N fell below the slack threshold "
                              f"{th.slack_tension:.0f} N"))
        self._slack = slack
        over = peak_tension > th.safe_working_load
        if over and not self._over:
            out.append(_event(t, "over_tension", peak_tension, th.safe_working_load,
                              f"element tension {peak_tension:.0f} N exceeded the safe working load "
                              f"{th.safe_working_load:.0f} N"))
        self._over = over
        if tether_broken(peak_tension, th.strength):
            out.append(_event(t, "break", peak_tension, th.strength,
                              f"element tension {peak_tension:.0f} N exceeded the tether strength "
                              f"{th.strength:.0f} N"))
        return out


def _event(t: float, name: str, value: float, threshold: float, message: str) -> dict:
    return {"time": float(t), "event": name, "message": message, "value": float(value),
            "threshold": float(threshold)}


# --- motor force (diagnostic) --------------------------------------------------------------------


def motor_force(model, x: np.ndarray, u: np.ndarray, t: float = 0.0) -> float:
    """Motor force at the line [N] implied by the compiled core's drum acceleration:
    F_m = m_eq v_w' - T_w + F_friction(v_w) (NaN while braked)."""
    if u[1] != 0.0:
        return math.nan
    lay = model.layout
    dx = model.rhs(x, u, t)
    Tw = model.work[tension_offset(model.n) + model.n - 1]
    v = x[lay.winch_speed]
    return model.params.winch.equivalent_mass * dx[lay.winch_speed] - Tw + winch_friction(v, model.p)
