"""State layout, input layout and work-array layout of the compiled core, written down once.

State vector (length 6 n + 8, n = number of tether elements)::

    [ r_2 .. r_n        3 (n-1)  inertial positions of the moving tether nodes, top to bottom [m]
      v_2 .. v_n        3 (n-1)  their inertial velocities [m/s]
      r_cm              3        aerostat CM position, inertial [m]
      v_cm              3        aerostat CM velocity, inertial components [m/s]
      phi, theta, psi   3        Z-Y-X Euler angles (roll, pitch, yaw) [rad]
      p, q, r           3        body angular rates [rad/s]
      L                 1        unstretched tether length paid out [m]
      v_w               1        winch reel-out speed (positive pays line out) [m/s] ]

The first 6 n + 6 entries are the mechanical state of [LN02] (66 for n = 10); the last two are
the winch. Node numbering follows [LN02]: node 1 is the confluence point, rigidly attached to
the aerostat (not a state), node n + 1 the anchor at the winch (fixed, not a state).

The aerostat block starts at ``aerostat_offset(n) = 6 (n - 1)``; its entries are named by the
``S_*`` offsets below (``x[aerostat_offset(n) + S_THETA]`` is the pitch angle). Compiled code
and Python code use the same names; :class:`StateLayout` gives the Python side slices.

Control input ``u = [v_set, brake]``: reel-out speed set-point [m/s] and brake flag (1 holds the
drum), indexed by ``U_SPEED`` and ``U_BRAKE``.

Work array (filled by every right-hand-side evaluation, read by the outputs): node positions,
velocities and forces, 3 (n + 1) each (node 0 = confluence point, node n = anchor), from
``node_pos_offset``, ``node_vel_offset`` and ``node_force_offset``; the n element tensions from
``tension_offset`` (top element first); the wind sample points (n element midpoints, the hull
point, the fin points) from ``points_offset``, each followed by its air velocity; then the
tether's per-element scratch from ``scratch_offset``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

from .packing import MAX_FINS

N_INPUTS = 2
U_SPEED, U_BRAKE = 0, 1

# --- offsets within the aerostat block of the state ------------------------------------------------
S_X, S_Y, S_Z = 0, 1, 2  # CM position, inertial [m]
S_VX, S_VY, S_VZ = 3, 4, 5  # CM velocity, inertial components [m/s]
S_PHI, S_THETA, S_PSI = 6, 7, 8  # Z-Y-X Euler angles [rad]; theta < 0 is nose up
S_P, S_Q, S_R = 9, 10, 11  # body rates [rad/s]
S_LENGTH = 12  # unstretched tether length paid out [m]
S_REEL = 13  # reel-out speed [m/s], positive pays out


@njit(cache=True, inline="always")
def aerostat_offset(n):
    """Index of the aerostat block (x_cm) in the state of n tether elements."""
    return 6 * (n - 1)


def state_size(n: int) -> int:
    return 6 * n + 8


# --- work array -------------------------------------------------------------------------------------


@njit(cache=True, inline="always")
def node_vel_offset(n):
    return 3 * (n + 1)


@njit(cache=True, inline="always")
def node_force_offset(n):
    return 6 * (n + 1)


@njit(cache=True, inline="always")
def tension_offset(n):
    """Index of the first (top) element tension in the work array."""
    return 9 * (n + 1)


@njit(cache=True, inline="always")
def points_offset(n):
    """Index of the wind sample points in the work array (their winds follow them)."""
    return 9 * (n + 1) + n


@njit(cache=True, inline="always")
def scratch_offset(n):
    """Index of the tether's per-element scratch (5 n floats) in the work array."""
    return 9 * (n + 1) + n + 6 * (n + 1 + MAX_FINS)


def work_size(n: int) -> int:
    return 9 * (n + 1) + n + 6 * (n + 1 + MAX_FINS) + 5 * n


@dataclass(frozen=True)
class StateLayout:
    """Named slices into the flat state vector for n tether elements (see module docstring)."""

    n_elements: int

    @property
    def n_nodes(self) -> int:
        """Moving tether nodes (excludes the confluence point and the anchor)."""
        return self.n_elements - 1

    @property
    def size(self) -> int:
        return state_size(self.n_elements)

    @property
    def aerostat(self) -> int:
        """Index of the aerostat block (offsets ``S_*`` count from here)."""
        return 6 * self.n_nodes

    @property
    def n_mechanical(self) -> int:
        return 6 * self.n_elements + 6

    def at(self, k: int) -> int:
        """Index of the aerostat-block entry ``k`` (an ``S_*`` offset), e.g. ``at(S_THETA)``,
        the pitch angle."""
        return self.aerostat + k

    @property
    def node_pos(self) -> slice:
        return slice(0, 3 * self.n_nodes)

    @property
    def node_vel(self) -> slice:
        return slice(3 * self.n_nodes, 6 * self.n_nodes)

    @property
    def cm_pos(self) -> slice:
        return slice(self.at(S_X), self.at(S_VX))

    @property
    def cm_vel(self) -> slice:
        return slice(self.at(S_VX), self.at(S_PHI))

    @property
    def euler(self) -> slice:
        return slice(self.at(S_PHI), self.at(S_P))

    @property
    def rates(self) -> slice:
        return slice(self.at(S_P), self.at(S_LENGTH))

    @property
    def winch_length(self) -> int:
        return self.at(S_LENGTH)

    @property
    def winch_speed(self) -> int:
        return self.at(S_REEL)

    @property
    def mechanical(self) -> slice:
        return slice(0, self.n_mechanical)

    def names(self) -> list[str]:
        """Human-readable name of every state entry (node k counts from the top, k = 2..n)."""
        out = []
        nodes = range(2, self.n_elements + 1)
        out += [f"{c}{k}" for k in nodes for c in "xyz"]
        out += [f"{c}dot{k}" for k in nodes for c in "xyz"]
        out += ["x_cm", "y_cm", "z_cm", "u_cm", "v_cm", "w_cm", "phi", "theta", "psi", "p", "q", "r"]
        return out + ["L", "v_w"]

    def longitudinal_indices(self) -> np.ndarray:
        """[LN02] longitudinal set: x, z and their rates for every node (aerostat last), theta, q.

        Order: x_2..x_n, x_cm, xdot_2..xdot_cm, z_2..z_cm, zdot_2..zdot_cm, theta, q
        (4 n + 2 states).
        """
        n = self.n_nodes
        pos = lambda c: [3 * k + c for k in range(n)] + [self.at(c)]  # noqa: E731
        vel = lambda c: [3 * n + 3 * k + c for k in range(n)] + [self.at(S_VX + c)]  # noqa: E731
        return np.array(pos(0) + vel(0) + pos(2) + vel(2) + [self.at(S_THETA), self.at(S_Q)])

    def lateral_indices(self) -> np.ndarray:
        """[LN02] lateral set: y and its rate for every node, phi, p, psi, r (2 n + 4 states)."""
        n = self.n_nodes
        ys = [3 * k + 1 for k in range(n)] + [self.at(S_Y)]
        vys = [3 * n + 3 * k + 1 for k in range(n)] + [self.at(S_VY)]
        return np.array(ys + vys + [self.at(S_PHI), self.at(S_P), self.at(S_PSI), self.at(S_R)])
