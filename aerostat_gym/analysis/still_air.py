"""Small oscillations of the rigid aerostat on a straight elastic tether in still air.

[LN02]'s reference frequencies (:mod:`aerostat_gym.analysis.reference`) treat the aerostat as a
buoyant point mass. The aerostat is a rigid body that hangs from the confluence point C with
its CM and CB above C, so its swing turns the hull as well: where the tether is not much longer
than the hull (a 16 m aerostat on 40 m: the linear pendulum 11 % longer than the point-mass
period), the pendulum and the pitching (or rolling) of the hull share one motion. Here the
aerostat keeps its mass, inertia tensor and added masses; the tether stays straight (a third
of its mass moves with C, its weight acts at mid-length, as in
:func:`~aerostat_gym.analysis.reference.tether_mass_periods`) and stretches elastically.

Generalized coordinates, all zero at the still-air trim (tether vertical, hull at the trim
pitch theta_0): the tether's swing angles towards inertial x and y, its stretch e along its
length, and the hull's small rotation vector delta in body axes. With C = (L + e) n(swing) and
a body point P at C + R_0 Exp(delta) r_P (r_P from C to P in body axes)::

    T = 1/2 v_b' M_e v_b + 1/2 delta_dot' I delta_dot + 1/2 (mu L / 3) |C_dot|^2,
        v_b = R_0' C_dot + delta_dot x r_M                      (CM velocity, body axes)
    V = (m g - B + mu g L / 2) C_z + m g z_M(delta) - B z_B(delta) + EA e^2 / (2 L)

with M_e = diag(m + k_i rho V) the effective masses at the CM, as in the simulation. Both forms
are quadratic in the coordinates and their rates, so the mass and stiffness matrices follow in
closed form (:func:`still_air_matrices`) and the periods from a 6 x 6 symmetric eigenproblem;
yaw about the vertical has no stiffness in still air (one zero frequency). The swing stiffness
is (B - m g - mu g L / 2) L per radian, the stretch stiffness EA / L, and the hull's rotation
stiffness sum_P w_P [(a r_P' + r_P a') / 2 - (a . r_P) 1] (w_M = m g, w_B = -B, a = R_0' z_hat),
from the second-order term [delta x]^2 / 2 of the rotation; the trim pitch makes the first-order
moment vanish (the leash position's definition). A point mass (r_M = r_B = 0) recovers the
pendulum and axial forms of :func:`~aerostat_gym.analysis.reference.tether_mass_periods`.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.linalg import eigh
from scipy.optimize import linear_sum_assignment

from ..params import Params, load_params
from ..physics.core import rotation_matrix

#: The generalized coordinates, in matrix order.
COORDINATES = ("swing_x", "swing_y", "stretch", "roll", "pitch", "yaw")
#: The mode each coordinate names (the yaw coordinate carries the zero-frequency mode).
MODE_OF_COORDINATE = {"swing_x": "long_pendulum", "swing_y": "lat_pendulum",
                      "stretch": "axial_spring", "roll": "rolling", "pitch": "pitching"}
#: omega^2 below this fraction of the largest is the free yaw of still air (no stiffness).
ZERO_FREQUENCY_RATIO = 1e-9


def _skew(r: np.ndarray) -> np.ndarray:
    """[r x]: the matrix of the cross product r x (.)."""
    return np.array([[0.0, -r[2], r[1]], [r[2], 0.0, -r[0]], [-r[1], r[0], 0.0]])


def still_air_matrices(params: Params | None = None, length: float | None = None):
    """Mass and stiffness matrices (6 x 6, :data:`COORDINATES` order) of the still-air model.

    Returns
    -------
    (M, K): kinetic and potential energy Hessians [kg m^2 or kg, N m or N/m per coordinate].
    """
    p = params or load_params()
    a, d, g = p.aerostat, p.derived, p.environment.g
    L = p.tether.length if length is None else length
    mu = d.mass_per_length
    R0 = rotation_matrix(0.0, math.radians(a.trim_pitch_deg), 0.0)
    r_leash = np.asarray(d.leash_position, float)
    r_cm = -r_leash                                  # C -> CM, body axes
    r_cb = np.asarray(a.cb_position, float) - r_leash  # C -> CB
    up = R0.T @ np.array([0.0, 0.0, 1.0])            # inertial up in body axes
    # C's velocity per coordinate rate at the trim: swings move it horizontally by L per
    # radian, the stretch moves it along the vertical tether.
    dC = np.zeros((3, 6))
    dC[0, 0] = dC[1, 1] = L
    dC[2, 2] = 1.0
    # CM velocity in body axes: R_0' C_dot + delta_dot x r_cm = R_0' C_dot - [r_cm x] delta_dot
    Jv = R0.T @ dC
    Jv[:, 3:] = -_skew(r_cm)
    M = Jv.T @ np.diag(d.effective_mass) @ Jv
    M[3:, 3:] += a.inertia_tensor
    M[:3, :3] += (mu * L / 3.0) * dC[:, :3].T @ dC[:, :3]
    K = np.zeros((6, 6))
    K[0, 0] = K[1, 1] = (d.net_lift - 0.5 * mu * g * L) * L
    K[2, 2] = d.EA / L
    for weight, r in ((a.mass * g, r_cm), (-d.buoyancy, r_cb)):
        K[3:, 3:] += weight * (0.5 * (np.outer(up, r) + np.outer(r, up)) - (up @ r) * np.eye(3))
    return M, K


def still_air_modes(params: Params | None = None, length: float | None = None) -> dict:
    """Periods [s] of the still-air model's modes, keyed like :data:`MODE_OF_COORDINATE`'s
    values: each mode is named by the coordinate that carries most of its kinetic energy
    (one mode per coordinate, by an optimal assignment, so two modes that share a motion
    equally still get one name each); the free yaw is left out.

    Raises
    ------
    ValueError
        If a mode other than the free yaw has a negative stiffness (the aerostat would not
        hang stably from its confluence point in still air).
    """
    M, K = still_air_matrices(params, length)
    w2, V = eigh(K, M)
    keep = np.abs(w2) > ZERO_FREQUENCY_RATIO * np.max(np.abs(w2))
    if np.any(w2[keep] < 0.0):
        raise ValueError("the aerostat does not hang stably in still air: a mode of the "
                         "rigid aerostat on its tether has negative stiffness")
    w2, V = w2[keep], V[:, keep]
    # kinetic-energy share of each coordinate in each (M-normalised) mode
    share = np.abs(V * (M @ V))
    coords = [i for i, c in enumerate(COORDINATES) if c in MODE_OF_COORDINATE]
    rows, cols = linear_sum_assignment(-share[coords, :])
    return {MODE_OF_COORDINATE[COORDINATES[coords[r]]]: 2.0 * math.pi / math.sqrt(w2[c])
            for r, c in zip(rows, cols, strict=True)}
