"""Total mechanical energy of the model, for conservation checks.

E = sum_j 1/2 m_node |v_j|^2 + 1/2 V_B . M_e V_B + 1/2 omega . I omega      (kinetic, added mass incl.)
  + sum_j m_node g z_j + 1/2 m_node g z_c + m g z_cm - B z_cb              (gravity, buoyancy)
  + sum_e 1/2 EA l_u eps_e^2  (eps_e > 0, tension-only elements)           (elastic)

The inertial terms of the core (Kirchhoff form) make this exactly conserved when drag,
aerodynamic forces and tether damping are switched off and the winch is braked.
"""

from __future__ import annotations

import numpy as np

from ..physics.core import rotation_matrix
from ..physics.state import S_Z
from ..sim import Model


def mechanical_energy(model: Model, x: np.ndarray) -> float:
    """Kinetic (with added mass) plus gravitational, buoyancy and elastic energy [J]."""
    lay, prm, d = model.layout, model.params, model.params.derived
    g, n = prm.environment.g, model.n
    L = x[lay.winch_length]
    l_u = L / n
    m_node = d.mass_per_length * l_u
    R = rotation_matrix(*x[lay.euler])
    vb = R.T @ x[lay.cm_vel]
    a = prm.aerostat
    om = x[lay.rates]
    kinetic = (0.5 * m_node * np.sum(x[lay.node_vel] ** 2)
               + 0.5 * vb @ (np.array(d.effective_mass) * vb) + 0.5 * om @ a.inertia_tensor @ om)
    nodes = model.node_positions(x)
    z_cb = x[lay.at(S_Z)] + (R @ np.array(a.cb_position))[2]
    potential = (m_node * g * np.sum(nodes[1:-1, 2]) + 0.5 * m_node * g * nodes[0, 2]
                 + a.mass * g * x[lay.at(S_Z)] - d.buoyancy * z_cb)
    lengths = np.linalg.norm(np.diff(nodes, axis=0), axis=1)
    eps = np.maximum(lengths / l_u - 1.0, 0.0)
    elastic = 0.5 * d.EA * l_u * np.sum(eps**2)
    return float(kinetic + potential + elastic)
