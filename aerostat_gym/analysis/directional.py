"""Static directional (weathercock) stability: the yaw moment the aerostat feels when its
heading is turned off the trim heading with everything else held at the trim.

The aerostat turns back into the wind where the fins' restoring moment exceeds the hull's
destabilising Munk moment. On the baseline the margin is modest (fins +201 against hull
-149 - 11 m^3/rad at the trim, docs/parameters.md 5.1), so independent draws of the fin lift
slope and the hull efficiency, two of the estimated parameters, can cancel it (a fifth less of
the one and a fifth more of the other do): such an aerostat does not weathervane, and in
turbulence it sails across the wind, 80-200 m off its trim (docs/parameters.md 5.5).
"""

from __future__ import annotations

import numpy as np

from ..physics.state import S_PSI, S_R
from ..sim import Model

#: [deg] yaw offsets at which a weathercock-stable aerostat's static yaw moment restores: the
#: band of sideslip that light turbulence reaches on the baseline (under 10 deg in episodes that
#: stay near their trim), sampled finely enough to catch a moment that turns within it
WEATHERCOCK_OFFSETS_DEG = (2.5, 5.0, 7.5, 10.0)


def static_yaw_acceleration(model: Model, x_trim: np.ndarray, offsets_deg) -> np.ndarray:
    """Yaw acceleration dr/dt [rad/s^2] at the trim state with the heading turned by each
    offset [deg] (positive turns the nose to starboard); a negative value turns it back."""
    lay = model.layout
    out = np.empty(len(offsets_deg))
    for k, deg in enumerate(offsets_deg):
        x = np.array(x_trim, dtype=float)
        x[lay.at(S_PSI)] += np.radians(deg)
        out[k] = model.rhs(x)[lay.at(S_R)]
    return out


def weathercock_stable(model: Model, x_trim: np.ndarray,
                       offsets_deg=WEATHERCOCK_OFFSETS_DEG) -> bool:
    """Whether the static yaw moment restores at every offset of ``offsets_deg``."""
    return bool(np.all(static_yaw_acceleration(model, x_trim, offsets_deg) < 0.0))
