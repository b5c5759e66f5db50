"""The packed parameter vector of the compiled core.

:func:`pack_params` flattens :class:`aerostat_gym.params.Params` (plus the derived quantities)
into one float64 array indexed by the ``P_*`` constants below, so the compiled functions take
plain arrays and numba folds the indices at compile time. The state layout is in
:mod:`aerostat_gym.physics.state`.
"""

from __future__ import annotations

import math

import numpy as np

from ..params import MAX_FIN_PANELS as MAX_FINS
from ..params import Params

# --- packed parameter vector ----------------------------------------------------------------------
_FIELDS = [
    ("G", 1), ("RHO", 1), ("MASS", 1), ("BUOY", 1), ("ME", 3), ("MA", 3), ("INERTIA", 9),
    ("IINV", 9), ("CB", 3), ("LEASH", 3), ("NOSE", 3),
    # hull (Jones & DeLaurier)
    ("KPOT", 1), ("I1", 1), ("I3", 1), ("J1", 1), ("J2", 1), ("CD0H", 1), ("SH", 1), ("CDC", 1),
    # fins
    ("NFIN", 1), ("AF", 1), ("CLA", 1), ("ASTALL", 1), ("CD0F", 1), ("KIND", 1),
    ("FIN", 9 * MAX_FINS),
    # tether
    ("NEL", 1), ("EA", 1), ("MU", 1), ("DASHPOT", 1), ("CDN", 1), ("DIAM", 1), ("FN", 5),
    ("FT", 6), ("ANCHOR", 3), ("STRENGTH", 1),
    # winch
    ("W_MEQ", 1), ("W_FC", 1), ("W_CV", 1), ("W_FMAX", 1), ("W_VMAX", 1), ("W_AMAX", 1),
    ("W_TAU", 1), ("W_LMIN", 1), ("W_LMAX", 1), ("W_FRICTION_V", 1),
    # 1 holds the aerostat fixed (tether-only runs, e.g. the comparison with MoorDyn)
    ("FIXED", 1),
    # large-angle fins: 1 Viterna-Corrigan post-stall, 0 [LN02]'s flat C_L; deep-stall C_D,max
    ("POSTSTALL", 1), ("CDMAX", 1),
    # 1: Froude-Krylov plus added-mass force of accelerating air on the hull; the length [m]
    # along the wind over which the air acceleration is averaged (the hull length)
    ("AIRINERTIA", 1), ("AILEN", 1),
]
# Offsets into the packed vector (literal, so numba folds them; checked against _FIELDS by the tests).
P_G = 0
P_RHO = 1
P_MASS = 2
P_BUOY = 3
P_ME = 4
P_MA = 7
P_INERTIA = 10
P_IINV = 19
P_CB = 28
P_LEASH = 31
P_NOSE = 34
P_KPOT = 37
P_I1 = 38
P_I3 = 39
P_J1 = 40
P_J2 = 41
P_CD0H = 42
P_SH = 43
P_CDC = 44
P_NFIN = 45
P_AF = 46
P_CLA = 47
P_ASTALL = 48
P_CD0F = 49
P_KIND = 50
P_FIN = 51
P_NEL = 105
P_EA = 106
P_MU = 107
P_DASHPOT = 108
P_CDN = 109
P_DIAM = 110
P_FN = 111
P_FT = 116
P_ANCHOR = 122
P_STRENGTH = 125
P_W_MEQ = 126
P_W_FC = 127
P_W_CV = 128
P_W_FMAX = 129
P_W_VMAX = 130
P_W_AMAX = 131
P_W_TAU = 132
P_W_LMIN = 133
P_W_LMAX = 134
P_W_FRICTION_V = 135
P_FIXED = 136
P_POSTSTALL = 137
P_CDMAX = 138
P_AIRINERTIA = 139
P_AILEN = 140
P_SIZE = 141


def pack_params(params: Params) -> np.ndarray:
    """Flatten :class:`Params` (plus derived quantities) into the compiled core's vector."""
    env, a, h, f, t, w = (params.environment, params.aerostat, params.hull, params.fins,
                          params.tether, params.winch)
    d = params.derived
    if len(f.panels) > MAX_FINS:
        raise ValueError(f"at most {MAX_FINS} fin panels are supported, got {len(f.panels)}")
    p = np.zeros(P_SIZE)
    p[P_G], p[P_RHO], p[P_MASS], p[P_BUOY] = env.g, env.rho_air, a.mass, d.buoyancy
    p[P_ME:P_ME + 3] = d.effective_mass
    p[P_MA:P_MA + 3] = d.added_mass
    inertia = a.inertia_tensor
    p[P_INERTIA:P_INERTIA + 9] = inertia.ravel()
    p[P_IINV:P_IINV + 9] = np.linalg.inv(inertia).ravel()
    p[P_CB:P_CB + 3] = a.cb_position
    p[P_LEASH:P_LEASH + 3] = d.leash_position
    p[P_NOSE:P_NOSE + 3] = a.nose_position
    p[P_KPOT] = (a.k3 - a.k1) * h.eta_k
    p[P_I1], p[P_I3], p[P_J1], p[P_J2] = h.I1, h.I3, h.J1, h.J2
    p[P_CD0H], p[P_SH], p[P_CDC] = h.CD0, d.reference_area, h.Cdc
    p[P_NFIN] = len(f.panels)
    p[P_AF], p[P_CLA], p[P_ASTALL], p[P_CD0F] = (f.planform_area, f.CL_alpha,
                                                 math.radians(f.alpha_stall_deg), f.CD0)
    p[P_KIND] = 1.0 / (math.pi * f.aspect_ratio * f.oswald_e)
    p[P_POSTSTALL] = 1.0 if f.post_stall == "viterna" else 0.0
    p[P_CDMAX] = d.fin_cd_max
    p[P_AIRINERTIA] = 1.0 if a.air_inertia else 0.0
    p[P_AILEN] = a.length
    for i, pan in enumerate(f.panels):
        g = math.radians(pan.roll_angle_deg)
        span = np.array([0.0, math.sin(g), math.cos(g)])
        normal = np.cross(span, [1.0, 0.0, 0.0])  # n = s x x: fin-plane normal ([LN02] fin alpha)
        p[P_FIN + 9 * i:P_FIN + 9 * i + 9] = np.concatenate([pan.cp_position, span, normal])
    p[P_NEL], p[P_EA], p[P_MU], p[P_DASHPOT] = t.n_elements, d.EA, d.mass_per_length, d.dashpot
    p[P_CDN], p[P_DIAM] = t.Cd_normal, t.diameter
    if len(t.loading_fn) != 5:
        raise ValueError(f"tether.loading_fn needs 5 coefficients, got {len(t.loading_fn)}")
    if len(t.loading_ft) != 6:
        raise ValueError(f"tether.loading_ft needs 6 coefficients, got {len(t.loading_ft)}")
    p[P_FN:P_FN + 5] = t.loading_fn
    p[P_FT:P_FT + 6] = t.loading_ft
    p[P_ANCHOR:P_ANCHOR + 3] = t.anchor_position
    p[P_STRENGTH] = t.strength
    p[P_W_MEQ], p[P_W_FC], p[P_W_CV] = w.equivalent_mass, w.coulomb_friction, w.viscous_friction
    p[P_W_FMAX], p[P_W_VMAX], p[P_W_AMAX] = w.max_motor_force, w.max_speed, w.max_acceleration
    p[P_W_TAU], p[P_W_LMIN], p[P_W_LMAX] = w.speed_time_constant, w.min_length, w.max_length
    p[P_W_FRICTION_V] = 0.01  # m/s: Coulomb friction smoothed as tanh(v / 0.01)
    return p
