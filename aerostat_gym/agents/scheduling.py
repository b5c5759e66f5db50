"""Gain scheduling over the mean wind speed, shared by the LQR, modal and LQG designs: the
design speeds covering a wind range, the trims the winch motor holds, the tables of designs
interpolated in the wind speed, the fade of the gains below the lowest design speed, and the
fingerprint of the parameter set a schedule was built for.
"""

from __future__ import annotations

import hashlib
import math

import numpy as np

from ..analysis.trim import find_equilibrium
from ..params import Params, dumps_toml


class LQRDesignError(RuntimeError):
    """The Riccati equation could not be solved or the loop it gives is not stable."""


#: Design wind speeds of the default schedule [m/s] (2, 3, ..., 16): the environment's default
#: range 3-15 m/s with one step of margin on each side (:func:`schedule_speeds`).
DEFAULT_SPEEDS = np.arange(2.0, 17.0, 1.0)
DEFAULT_SPEEDS.setflags(write=False)
#: Step of the design speeds and the margin beyond the wind range [m/s].
SCHEDULE_STEP = 1.0


def schedule_speeds(wind_range: tuple[float, float]) -> np.ndarray:
    """Design speeds covering a wind range (low, high) [m/s] with one step of margin on each
    side, never below 1 m/s (at zero wind the yaw mode is neutral); (3, 15) gives 2, 3, ..., 16."""
    lo, hi = (float(v) for v in wind_range)
    if not (math.isfinite(lo) and math.isfinite(hi) and 0 <= lo <= hi):
        raise ValueError(f"wind range must be finite with 0 <= low <= high, got {wind_range!r}")
    start = max(lo - SCHEDULE_STEP, 1.0)
    n = int(math.ceil((hi + SCHEDULE_STEP - start) / SCHEDULE_STEP - 1e-9)) + 1
    return start + SCHEDULE_STEP * np.arange(n)


def covering_speeds(wind_range: tuple[float, float]) -> np.ndarray | None:
    """Design speeds of a schedule that keeps :data:`DEFAULT_SPEEDS` and covers the top of
    ``wind_range`` (low, high) [m/s]: None (the default table) where ``high`` is at most its
    top 16 m/s, else the default speeds continued in :data:`SCHEDULE_STEP` to one step above
    ``high`` ((20, 25) gives 2, 3, ..., 26).

    Above the top design speed the interpolated gains clamp to those designed there, for a
    dynamic pressure (U / 16 m/s)^2 times smaller than the wind's; below the lowest they
    fade to the braked winch instead (:func:`low_wind_fade`: a design at 1 m/s did not damp
    the pendulum better), so the low end stays the default's. The default speeds are kept
    exactly, so the gains inside 2-16 m/s are the default table's."""
    hi = float(wind_range[1])
    if hi <= DEFAULT_SPEEDS[-1]:
        return None
    return schedule_speeds((float(DEFAULT_SPEEDS[0]) + SCHEDULE_STEP, hi))


def low_wind_fade(U, lowest: float) -> np.ndarray:
    """Factor on a schedule's feedback gains at wind speed U below its lowest design speed
    ``lowest``: (U / lowest)^2, 1 from ``lowest`` up, 0 at zero wind (the braked winch).

    Reeling moves the aerostat across the wind through the blow-by angle, whose tangent (drag
    over net lift) grows as U^2 at low wind: the winch's authority over the pendulum at the
    trim vanishes as U -> 0, and gains designed at ``lowest`` ask for reeling it cannot turn
    into damping. Unfaded, they saturated the reel through a 10 m swing and the pendulum grew:
    the modal controller at 1 m/s on its 2 m/s gains, zeta -0.031 against the braked winch's
    0.034; faded with the authority, 0.041 (README, "Below the design range")."""
    return np.clip(np.asarray(U, float) / lowest, 0.0, 1.0) ** 2


def scheduled_tables(speeds: np.ndarray, tables: dict, U, faded=frozenset()) -> dict:
    """Each table of ``tables`` (one row per design speed in ``speeds``) at the wind speeds U
    (scalar or (N,)): linear in U between the design speeds, clamped to the end speeds; the
    tables named in ``faded`` (feedback gains) times :func:`low_wind_fade` below the lowest."""
    U = np.asarray(U, float)
    if speeds.size == 1:
        out = {k: np.broadcast_to(v[0], U.shape + v.shape[1:]) for k, v in tables.items()}
    else:
        Uc = np.clip(U, speeds[0], speeds[-1])
        i = np.clip(np.searchsorted(speeds, Uc, side="right") - 1, 0, speeds.size - 2)
        w = (Uc - speeds[i]) / (speeds[i + 1] - speeds[i])
        out = {}
        for k, v in tables.items():
            ww = w.reshape(w.shape + (1,) * (v.ndim - 1))
            out[k] = (1.0 - ww) * v[i] + ww * v[i + 1]
    fade = low_wind_fade(U, speeds[0])
    for k in set(faded).intersection(out):
        out[k] = out[k] * fade.reshape(fade.shape + (1,) * (out[k].ndim - fade.ndim))
    return out


def held_trims(params: Params, speeds) -> list:
    """(U, trim) at each design speed (non-negative, strictly increasing) whose trim the winch
    motor holds: winch tension at most ``winch.max_motor_force``. Above that speed a feedback
    design has no actuator (the over-hauled winch holds on its brake,
    :func:`aerostat_gym.sim.winch.brake_rule`, and its linearization has no control over the
    drum), so a schedule stops there and its gains stay those of the last held speed. Trims
    by continuation in U. Raises LQRDesignError when the motor holds none of them."""
    speeds = np.asarray(speeds, float).ravel()
    if speeds.size == 0 or np.any(np.diff(speeds) <= 0) or np.any(speeds < 0):
        raise ValueError(f"speeds must be non-negative and strictly increasing, got {speeds}")
    fmax, held, eq = params.winch.max_motor_force, [], None
    for U in speeds:
        eq = find_equilibrium(params, float(U), guess=eq)
        if eq.summary["winch_tension_N"] > fmax:
            break
        held.append((float(U), eq))
    if not held:
        raise LQRDesignError(f"the winch motor (winch.max_motor_force = {fmax:.0f} N) cannot "
                             f"hold the trim at any design speed from {speeds[0]:g} m/s: no "
                             "feedback design")
    return held


def params_fingerprint(params: Params) -> str:
    """SHA-256 of the parameter set's TOML text (identifies the model a schedule was built for)."""
    return hashlib.sha256(dumps_toml(params).encode()).hexdigest()
