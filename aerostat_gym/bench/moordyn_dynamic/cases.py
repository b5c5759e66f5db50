"""The compared cases: the prescribed paths of the top end (sinusoid, reel, drop), packed
for the compiled drivers, and the standard case list."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from ...analysis.reference import reference_periods
from ...params import Params

WINDOW = 60.0  # s compared


DIRECTIONS = {"along": (1.0, 0.0, 0.0), "across": (0.0, 1.0, 0.0), "vertical": (0.0, 0.0, 1.0)}

# path kinds and the packed path vector (read by the compiled drivers)
SINE, DROP, REEL = 0, 1, 2
K_KIND, K_TOP, K_DIR, K_LEVER = 0, 1, 4, 7  # kind; trim top end (3); direction (3); CM - top (3)
K_AMP, K_OMEGA = 10, 11  # sine: amplitude [m], angular frequency [rad/s]
K_L0, K_REEL_V, K_REEL_T = 12, 13, 14  # reel: initial length [m], rate [m/s], duration [s]
K_DROP_D, K_DROP_T, K_HOLD_T, K_RISE_T = 15, 16, 17, 18  # drop: depth [m], fall, hold, rise [s]
PATH_SIZE = 19


class DynamicBenchError(ValueError):
    """Invalid input to the dynamic comparison (unknown case, variant or bad option)."""


# --- the prescribed path ---------------------------------------------------------------------


@dataclass(frozen=True)
class DrivenCase:
    """One prescribed top-end motion (see :mod:`aerostat_gym.bench.moordyn_dynamic`).

    Parameters
    ----------
    name : str
        Label in the table.
    kind : int
        ``SINE``, ``DROP`` or ``REEL``.
    direction : tuple of float
        Unit vector of the sinusoidal motion (inertial; +X along the wind, +Z up).
    amplitude : float
        Sine amplitude [m].
    period : float
        Sine period [s].
    reel_speed : float
        Rate of change of the unstretched length [m/s] (positive pays out).
    reel_time : float
        Duration of the length change [s].
    drop_depth : float
        Depth of the vertical drop [m].
    drop_time : float
        Duration of the fall [s].
    hold_time : float
        Time held at the bottom [s].
    rise_time : float
        Duration of the rise back to the trim [s].
    window : float
        Length of the compared window [s].
    """

    name: str
    kind: int
    direction: tuple = (0.0, 0.0, 1.0)
    amplitude: float = 0.0
    period: float = 0.0
    reel_speed: float = 0.0
    reel_time: float = 0.0
    drop_depth: float = 0.0
    drop_time: float = 0.0
    hold_time: float = 0.0
    rise_time: float = 0.0
    window: float = WINDOW

    @property
    def window_start(self) -> float:
        """Start of the compared window [s]: after the first cycle of a sine, else 0."""
        return self.period if self.kind == SINE else 0.0

    @property
    def duration(self) -> float:
        """Simulated time from the start of the drive to the end of the window [s]."""
        return self.window_start + self.window

    def pack(self, top: np.ndarray, lever: np.ndarray, length: float) -> np.ndarray:
        """Path vector for the compiled drivers.

        Parameters
        ----------
        top : ndarray
            Trim position of the top end (confluence point) [m].
        lever : ndarray
            CM minus confluence point at the trim attitude [m].
        length : float
            Unstretched length at the start [m].
        """
        v = np.zeros(PATH_SIZE)
        v[K_KIND] = self.kind
        v[K_TOP:K_TOP + 3] = top
        v[K_DIR:K_DIR + 3] = np.asarray(self.direction, float) / np.linalg.norm(self.direction)
        v[K_LEVER:K_LEVER + 3] = lever
        v[K_AMP] = self.amplitude
        v[K_OMEGA] = 2.0 * math.pi / self.period if self.period > 0 else 0.0
        v[K_L0] = length
        v[K_REEL_V], v[K_REEL_T] = self.reel_speed, self.reel_time
        v[K_DROP_D], v[K_DROP_T] = self.drop_depth, self.drop_time
        v[K_HOLD_T], v[K_RISE_T] = self.hold_time, self.rise_time
        return v


def standard_cases(params: Params) -> list[DrivenCase]:
    """The issue's table: 3 directions x 3 periods x 2 amplitudes, the reel and the drop."""
    ref = reference_periods(params)
    periods = {"pendulum": ref["long_pendulum"], "harmonic": ref["tether_1st"],
               "axial": ref["axial_spring"]}
    cases = [DrivenCase(f"{d}-{pn}-{a:g}m", SINE, DIRECTIONS[d], float(a), float(T))
             for d in DIRECTIONS for pn, T in periods.items() for a in (1.0, 5.0)]
    cases.append(DrivenCase("reel-out-1m/s-10s", REEL, reel_speed=1.0, reel_time=10.0))
    cases.append(drop_case())
    return cases


def drop_case() -> DrivenCase:
    """The slack case: a 20 m vertical drop in 2 s, held 3 s, back up in 4 s."""
    return DrivenCase("drop-20m-slack", DROP, drop_depth=20.0, drop_time=2.0, hold_time=3.0,
                      rise_time=4.0)


@njit(cache=True)
def _cosine_ramp(distance, duration, tau):
    """Displacement and rate of a cosine ramp over ``distance`` in ``duration`` at time tau."""
    a = math.pi / duration
    return 0.5 * distance * (1.0 - math.cos(a * tau)), 0.5 * distance * a * math.sin(a * tau)


@njit(cache=True)
def path_displacement(path, t):
    """Displacement of the top end along the path direction and its rate at time t (0 before
    the drive starts): s, ds/dt [m, m/s]."""
    if t <= 0.0:
        return 0.0, 0.0
    kind = int(path[K_KIND])
    if kind == SINE:
        w = path[K_OMEGA]
        return path[K_AMP] * math.sin(w * t), path[K_AMP] * w * math.cos(w * t)
    if kind == DROP:
        D, t1 = path[K_DROP_D], path[K_DROP_T]
        t2 = t1 + path[K_HOLD_T]
        t3 = t2 + path[K_RISE_T]
        if t < t1:
            s, sd = _cosine_ramp(D, t1, t)
            return -s, -sd
        if t < t2:
            return -D, 0.0
        if t < t3:
            s, sd = _cosine_ramp(D, path[K_RISE_T], t - t2)
            return s - D, sd
    return 0.0, 0.0


@njit(cache=True)
def path_length(path, t):
    """Unstretched length and its rate at time t [m, m/s] (constant except for the reel)."""
    if int(path[K_KIND]) != REEL or t <= 0.0:
        return path[K_L0], 0.0
    tr = min(t, path[K_REEL_T])
    return path[K_L0] + path[K_REEL_V] * tr, path[K_REEL_V] if t < path[K_REEL_T] else 0.0
