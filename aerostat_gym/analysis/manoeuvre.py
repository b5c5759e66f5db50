"""Reel-out / reel-in manoeuvre of the winch in a steady wind (a scenario built on the
simulator; ``scripts/winch_manoeuvre.py`` runs and plots it)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..extras import agg_pyplot
from ..params import Params, load_params
from ..physics.state import StateLayout
from ..sim.simulate import simulate
from .trim import find_equilibrium


@dataclass
class Manoeuvre:
    """A reel-out/reel-in run: the trajectory, the trim it started from and its schedule."""

    trajectory: object
    equilibrium: object
    target_length: np.ndarray = field(repr=False)
    reel_in_time: float = 0.0


def length_hold_law(target, speed: float, gain: float, length_index: int):
    """u(t, x): set-point clip(gain (L_target(t) - L), +-speed), brake released; the winch's
    brake rule engages the brake once |set-point| < brake_speed (near the target).
    ``length_index`` is :attr:`StateLayout.winch_length`."""

    def u(t, x):
        L = x[length_index]
        return [min(max(gain * (target(t) - L), -speed), speed), 0.0]

    return u


def reel_manoeuvre(params: Params | None = None, wind_speed: float = 10.0, distance: float = 50.0,
                   speed: float | None = None, hold: float = 30.0, settle: float = 300.0,
                   integrator: str = "rk4", dt: float | None = None, output_dt: float = 0.1,
                   gain: float = 1.0) -> Manoeuvre:
    """Reel out ``distance`` metres from the trim and back, in a steady wind (a negative
    distance reels in first).

    From the trim at the configured tether length and ``wind_speed``, the length target is
    L0 + distance until ``reel_in_time`` = |distance| / speed + hold, then L0; the set-point is
    clip(gain (target - L), +-speed) (default speed: the winch's speed limit) and the brake
    engages near each target. The run lasts reel_in_time + |distance| / speed + settle seconds.
    """
    params = params or load_params()
    speed = params.winch.max_speed if speed is None else float(speed)
    if not (math.isfinite(speed) and speed > 0):
        raise ValueError(f"speed must be finite and > 0, got {speed!r}")
    for name, value in (("hold", hold), ("settle", settle)):
        if not (math.isfinite(value) and value >= 0):
            raise ValueError(f"{name} must be a finite time >= 0 s, got {value!r}")
    eq = find_equilibrium(params, wind_speed)
    iL = StateLayout(params.tether.n_elements).winch_length
    L0 = float(eq.x[iL])
    w = params.winch
    if not (math.isfinite(distance) and w.min_length <= L0 + distance <= w.max_length):
        raise ValueError(f"distance must keep the tether within the winch's limits "
                         f"[{w.min_length:g}, {w.max_length:g}] m from the trim's {L0:g} m: "
                         f"[{w.min_length - L0:g}, {w.max_length - L0:g}] m, got {distance!r}")
    travel = abs(distance) / speed  # each way, at the top speed
    t_in = travel + hold

    def target(t):
        return L0 + distance if t < t_in else L0

    duration = t_in + travel + settle
    tr = simulate(params, eq.x, duration, wind=wind_speed, integrator=integrator, dt=dt,
                  output_dt=output_dt, u=length_hold_law(target, speed, gain, iL))
    targets = np.array([target(t) for t in tr.time])
    return Manoeuvre(trajectory=tr, equilibrium=eq, target_length=targets, reel_in_time=t_in)


def plot_manoeuvre(result: Manoeuvre, path) -> None:
    """Length, reel speed, winch tension and aerostat altitude against time, into ``path``."""
    plt = agg_pyplot("the manoeuvre figure")

    tr = result.trajectory
    fig, ax = plt.subplots(4, 1, figsize=(8, 9), sharex=True)
    ax[0].plot(tr.time, tr.length, label="L")
    ax[0].plot(tr.time, result.target_length, "--", label="target")
    ax[0].set_ylabel("length paid out [m]")
    ax[0].legend(loc="best")
    ax[1].plot(tr.time, tr.reel_speed, label="v_w")
    ax[1].step(tr.time[:-1], tr.v_set, where="post", lw=0.8, label="set-point")
    ax[1].set_ylabel("reel-out speed [m/s]")
    ax[1].legend(loc="best")
    ax[2].plot(tr.time, tr.load_cell, label="winch (load cell)")
    ax[2].plot(tr.time, tr.top_tension, lw=0.8, label="aerostat end")
    ax[2].set_ylabel("tension [N]")
    ax[2].legend(loc="best")
    ax[3].plot(tr.time, tr.cm_pos[:, 2])
    ax[3].set_ylabel("aerostat altitude [m]")
    ax[3].set_xlabel("time [s]")
    U = result.equilibrium.wind_speed
    fig.suptitle(f"Reel-out / reel-in at U = {U:g} m/s ({tr.status})")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
