"""Measured outputs computed from the compiled core's work array (shared by the simulator's
Python outputs and the environment's compiled step, so both read the same numbers)."""

from __future__ import annotations

import math

from numba import njit

from .core import FASTMATH
from .packing import P_G, P_MU, P_NEL
from .state import S_LENGTH, aerostat_offset, node_force_offset, tension_offset


@njit(cache=True, error_model="numpy", fastmath=FASTMATH)
def winch_tension(x, p, w):
    """Tether tension at the winch end [N], from a work array filled by ``evaluate_tether``.

    A lumped element carries the continuous tether's tension at its midpoint; the winch end
    differs by the weight of the half element lumped at the anchor:
    |T e - (mu l_u / 2) g z_hat|, e the unit vector of the last element pointing up the tether.
    """
    n = int(p[P_NEL])
    a = 3 * (n - 1)  # second-to-last node; the anchor follows at 3 n
    dx = w[a] - w[a + 3]
    dy = w[a + 1] - w[a + 4]
    dz = w[a + 2] - w[a + 5]
    inv = 1.0 / math.sqrt(dx * dx + dy * dy + dz * dz)
    T = w[tension_offset(n) + n - 1]
    half = 0.5 * p[P_MU] * x[aerostat_offset(n) + S_LENGTH] / n * p[P_G]
    fx, fy, fz = T * dx * inv, T * dy * inv, T * dz * inv - half
    return math.sqrt(fx * fx + fy * fy + fz * fz)


@njit(cache=True, error_model="numpy", fastmath=FASTMATH)
def confluence_tension(p, w):
    """Tether tension at the aerostat end [N]: magnitude of the total tether force at the
    confluence point (element 0 plus the half element lumped there)."""
    F = node_force_offset(int(p[P_NEL]))
    return math.sqrt(w[F] ** 2 + w[F + 1] ** 2 + w[F + 2] ** 2)
