"""The longitudinal state seen in the swing plane: a lateral swing's geometric dip removed.

A lateral swing turns the tether about the winch out of the trim plane (the vertical plane of
the mean wind, XZ). A point at distance r from the winch, turned through the angle beta along
its great circle, keeps (x, z) = (x0, z0) cos(beta): its along-wind and vertical coordinates dip
at second order in the swing, at twice its frequency. A feedback designed on the decoupled
longitudinal model reads that dip as longitudinal motion. Where the longitudinal pendulum's
frequency is near twice the lateral one (0.05 x the baseline's volume on 60 m: 16 s and 32 s),
the dip lies in the band the loop damps. The loop then reels at twice the swing frequency, and a
length modulated at twice a pendulum's frequency pumps that pendulum (parametric resonance):
the LQR took a 5 m lateral start there to a 17-18 m limit cycle with the reel saturated, while
the braked winch let it decay.

:func:`in_swing_plane` maps every tether node and the aerostat's CM back into the trim plane
along its great circle through the winch, (x', z') = (x, z) r / |(x, z)|, with the velocities
that follow. A rigid rotation about the winch out of the plane then leaves the longitudinal
coordinates where they were; the lateral coordinate y is kept. A state with y = 0 maps to
itself exactly (bit for bit), so a purely longitudinal motion reads as before.
"""

from __future__ import annotations

import numpy as np

from ..physics.state import StateLayout

#: Along-wind, lateral and vertical components of an inertial point.
_X, _Y, _Z = 0, 1, 2


def swing_plane_points(pos: np.ndarray, vel: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Points ``pos`` [m] and velocities ``vel`` [m/s], shape (..., 3), winch at the origin,
    mapped into the trim plane: x' = s x, z' = s z with s = r / rho (r = |p|, rho = |(x, z)|),
    and x'' = s vx + s' x, z'' = s vz + s' z with s' = s (r'/r - rho'/rho); y and vy kept.
    A point on the vertical through the winch (rho = 0) is kept as it is."""
    x, y, z = pos[..., _X], pos[..., _Y], pos[..., _Z]
    vx, vz = vel[..., _X], vel[..., _Z]
    rho2 = x * x + z * z
    on_axis = rho2 == 0.0
    rho2 = np.where(on_axis, 1.0, rho2)
    r2 = rho2 + y * y
    s = np.where(on_axis, 1.0, np.sqrt(r2 / rho2))
    r_rate = (x * vx + y * vel[..., _Y] + z * vz) / r2  # r' / r
    rho_rate = (x * vx + z * vz) / rho2  # rho' / rho
    s_rate = np.where(on_axis, 0.0, s * (r_rate - rho_rate))
    pos_out, vel_out = pos.copy(), vel.copy()
    pos_out[..., _X], pos_out[..., _Z] = s * x, s * z
    vel_out[..., _X], vel_out[..., _Z] = s * vx + s_rate * x, s * vz + s_rate * z
    return pos_out, vel_out


def in_swing_plane(dx: np.ndarray, x_ref: np.ndarray, layout: StateLayout) -> np.ndarray:
    """State deviations ``dx`` (N, 6n+8) from the reference states ``x_ref`` (N, 6n+8; a trim
    near the one ``dx`` is taken from) with every node and the CM read in the swing plane
    (:func:`swing_plane_points` on x_ref + dx). Only the change the map makes is added to
    ``dx``, so a deviation with no lateral part is returned unchanged to the last bit."""
    x = x_ref + dx
    out = dx.copy()
    n = dx.shape[0]
    for pos, vel in ((layout.node_pos, layout.node_vel), (layout.cm_pos, layout.cm_vel)):
        p = x[:, pos].reshape(n, -1, 3)
        v = x[:, vel].reshape(n, -1, 3)
        p_in, v_in = swing_plane_points(p, v)
        out[:, pos] += (p_in - p).reshape(n, -1)
        out[:, vel] += (v_in - v).reshape(n, -1)
    return out
