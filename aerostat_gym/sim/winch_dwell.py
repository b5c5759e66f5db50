"""Dwell-time brake logic for the ground winch (a proposal; the environment still uses
:func:`aerostat_gym.sim.winch.brake_rule`).

The shipped rule engages the brake at every control step whose set-point is below
``winch.brake_speed`` (0.02 m/s). A linear controller's command passes through that band twice
per pendulum period and stays inside it for the whole tail of a small swing, so its small
commands are lost: at a 0.5 m swing the LQR equals the braked winch. A real winch's parking
brake is applied by its supervisory logic only once the drive has been asked to stand still for
a while, so here the brake is wanted when

- it is commanded, or the set-point is exactly 0 (the environment's action 0, the passive
  braked winch, keeps its meaning), or
- |v_set| has stayed below ``brake_speed`` (the stand-still band; proposed
  :data:`DEFAULT_STANDSTILL_BAND` = 0.002 m/s) for at least ``dwell`` seconds (``quiet``
  counts that time and restarts at 0 whenever |v_set| >= brake_speed).

Until then a small set-point goes to the speed loop unchanged. Once wanted, the brake clamps the
drum as before: at once if it already held it or once |v_w| <= ``hold_speed``; meanwhile the
speed loop decelerates the drum with set-point 0. The default dwell, 10 s, is a quarter of the
pendulum period (36-45 s over 5-15 m/s): a command that crosses zero on its way to the other
sign never trips it, while a command that has settled engages the brake within 10 s.

With ``dwell = 0`` the rule is the shipped :func:`aerostat_gym.sim.winch.brake_rule` step for step.
"""

from __future__ import annotations

from numba import njit

from .winch import brake_rule

#: Time the set-point must stay inside the stand-still band before the brake is applied [s].
DEFAULT_DWELL_TIME = 10.0
#: Stand-still band of the set-point [m/s]: a tenth of the shipped 0.02 m/s dead band. With the
#: 0.02 m/s band and a 10 s dwell the brake still sets in the tail of a small swing and cuts it
#: (measured, 0.5 m swing at 15 m/s: LQR 0.384 against its linear 0.581); with 0.002 m/s every
#: baseline's damping is within 4 % of its linear value at 0.5, 1 and 10 m swings.
DEFAULT_STANDSTILL_BAND = 0.002


@njit(cache=True)
def dwell_brake_rule(v, brake_cmd, braked, v_w, quiet, dt, max_speed, brake_speed, hold_speed,
                     dwell):
    """One control step of the dwell-time brake logic; returns (v_set, brake, v_w, quiet).

    Parameters
    ----------
    v : float
        Requested set-point [m/s].
    brake_cmd : bool
        The brake is commanded explicitly.
    braked : bool
        The brake held the drum over the previous step.
    v_w : float
        Reel speed at the start of the step [m/s].
    quiet : float
        Time the set-point has stayed below brake_speed before this step [s].
    dt : float
        Control step [s].
    max_speed : float
        Set-point limit [m/s].
    brake_speed : float
        Set-points below this count as "stand still" [m/s].
    hold_speed : float
        The brake clamps the drum once |v_w| is at most this [m/s].
    dwell : float
        Stand-still time after which the brake is applied [s].

    Returns
    -------
    tuple
        (set-point sent to the speed loop, brake flag, reel speed after a possible clamp,
        updated stand-still time).
    """
    if abs(v) < brake_speed:
        quiet = quiet + dt
    else:
        quiet = 0.0
    want = brake_cmd or v == 0.0 or (abs(v) < brake_speed and quiet >= dwell - 1e-9)
    v_set, brake, v_w = brake_rule(v, want, braked, v_w, max_speed, 0.0, hold_speed)
    return v_set, brake, v_w, quiet


class DwellBrake:
    """The dwell-time rule as a set-point filter for :func:`aerostat_gym.simulation.simulate`
    (which applies the shipped rule inside; run it with ``winch.brake_speed = 0`` so that only
    this rule's explicit brake command engages the brake).

    Parameters
    ----------
    brake_speed : float
        Stand-still band of the set-point [m/s].
    dt : float
        Control step [s].
    dwell : float
        Stand-still time before the brake is applied [s].
    """

    def __init__(self, brake_speed: float, dt: float, dwell: float = DEFAULT_DWELL_TIME):
        if not (brake_speed >= 0 and dt > 0 and dwell >= 0):
            raise ValueError(f"dwell brake needs brake_speed >= 0, dt > 0, dwell >= 0; got "
                             f"{brake_speed!r}, {dt!r}, {dwell!r}")
        self.brake_speed, self.dt, self.dwell = float(brake_speed), float(dt), float(dwell)
        self.quiet = 0.0
        self.n_braked = 0

    def __call__(self, v: float) -> list:
        """[v_set, brake] for the requested set-point v (the input simulate() expects)."""
        if abs(v) < self.brake_speed:
            self.quiet += self.dt
        else:
            self.quiet = 0.0
        want = v == 0.0 or (abs(v) < self.brake_speed and self.quiet >= self.dwell - 1e-9)
        self.n_braked += int(want)
        return [0.0, 1.0] if want else [float(v), 0.0]
