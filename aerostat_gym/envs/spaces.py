"""The environment's observation table, reward terms and termination codes, written down once.

Every observation channel is a physical quantity divided by its scale, clipped to finite bounds.
Frames and signs (as everywhere in the package, see the README): inertial X, Y, Z with Z up and
the winch at the origin; the default wind blows along +X; attitude is the Z-Y-X Euler triple
(roll phi, pitch theta nose up positive, yaw psi; at trim psi = pi, the nose into the wind);
body rates p, q, r about the body x (nose), y and z axes; a positive reel speed pays line out.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Channel:
    """One observation channel: value = quantity / scale, clipped to +-limit (or [lo, hi])."""

    name: str
    meaning: str
    unit: str
    scale: float
    low: float
    high: float


def _ch(name, meaning, unit, scale, limit_si, low_si=None):
    lo = -limit_si if low_si is None else low_si
    return Channel(name, meaning, unit, scale, lo / scale, limit_si / scale)


#: The standard observation, in order (index = position in the vector).
CHANNELS: tuple[Channel, ...] = (
    _ch("dx", "aerostat CM position minus trim, X (along the mean wind)", "m", 10.0, 400.0),
    _ch("dy", "aerostat CM position minus trim, Y (lateral)", "m", 10.0, 400.0),
    _ch("dz", "aerostat CM position minus trim, Z (up)", "m", 10.0, 400.0),
    _ch("vx", "aerostat CM velocity, X", "m/s", 2.0, 50.0),
    _ch("vy", "aerostat CM velocity, Y", "m/s", 2.0, 50.0),
    _ch("vz", "aerostat CM velocity, Z", "m/s", 2.0, 50.0),
    _ch("droll", "roll phi minus trim", "rad", 0.05, np.pi),
    _ch("dpitch", "pitch theta minus trim (nose up positive)", "rad", 0.05, np.pi),
    _ch("dyaw", "yaw psi minus trim, wrapped to [-pi, pi]", "rad", 0.05, np.pi),
    _ch("p", "body roll rate", "rad/s", 0.02, 2.0),
    _ch("q", "body pitch rate", "rad/s", 0.02, 2.0),
    _ch("r", "body yaw rate", "rad/s", 0.02, 2.0),
    _ch("tension", "winch tension (load cell, winch-end tether tension)", "N", 1.0e4, 1.0e5,
        0.0),
    _ch("dtension", "winch tension minus its trim value", "N", 1.0e3, 1.0e5),
    _ch("dlength", "tether length paid out minus trim", "m", 10.0, 250.0),
    _ch("reel_speed", "winch reel speed (positive pays out)", "m/s", 1.0, 2.0),
    _ch("wind_x", "measured air velocity at the aerostat CM, X", "m/s", 10.0, 60.0),
    _ch("wind_y", "measured air velocity at the aerostat CM, Y", "m/s", 10.0, 60.0),
    _ch("wind_z", "measured air velocity at the aerostat CM, Z", "m/s", 10.0, 60.0),
)
N_OBS = len(CHANNELS)
#: Bound of the privileged full-state part (SI deviations from trim, and the mean wind speed).
FULL_STATE_LIMIT = 1.0e4

#: Reward terms, in the order of the compiled step's output; info carries "reward_<name>".
REWARD_TERMS: tuple[str, ...] = ("displacement", "velocity", "pitch", "pitch_rate", "effort",
                                 "effort_rate", "over_tension", "termination", "length")
REWARD_DOC = {
    "displacement": "-w (dx^2 + dy^2), scaled horizontal position channels 0-1 (blow-by)",
    "velocity": "-w (vx^2 + vy^2), scaled horizontal velocity channels 3-4",
    "pitch": "-w dpitch^2, scaled channel 7",
    "pitch_rate": "-w q^2, scaled channel 10",
    "effort": "-w a^2, a the action in [-1, 1]",
    "effort_rate": "-w (a - a_previous)^2",
    "over_tension": "-w max(0, peak element tension / safe working load - 1) over the step",
    "termination": "-w once, on a terminating step (break, ground strike, length limit, "
                   "numerical failure)",
    "length": "-w dlength^2, scaled channel 14: keeps the winch near its trim length on average",
}
#: The pendulum (blow-by) oscillation carries the weight: horizontal velocity first, horizontal
#: displacement next. Pitch and pitch rate are weighted lightly because any reeling excites pitch,
#: so heavy weights there would make the braked winch unbeatable (measured with the baselines).
DEFAULT_WEIGHTS = {"displacement": 0.2, "velocity": 1.0, "pitch": 0.1, "pitch_rate": 0.1,
                   "effort": 0.01, "effort_rate": 0.1, "over_tension": 10.0, "termination": 100.0,
                   "length": 1.0}

#: Step outcome codes of the compiled step.
RUNNING, NONFINITE, TETHER_BREAK, GROUND_STRIKE, LENGTH_LIMIT, FIELD_END = range(6)
#: Reason strings in info["termination"] / info["failure"] / info["truncation"].
OUTCOMES = {NONFINITE: "nonfinite_state", TETHER_BREAK: "tether_break",
            GROUND_STRIKE: "ground_strike", LENGTH_LIMIT: "length_limit",
            FIELD_END: "wind_field_exhausted"}


def observation_table(full_state_size: int = 0) -> list[dict]:
    """Rows (index, name, meaning, unit, scale, low, high) of the observation vector."""
    rows = [{"index": i, "name": c.name, "meaning": c.meaning, "unit": c.unit, "scale": c.scale,
             "low": c.low, "high": c.high} for i, c in enumerate(CHANNELS)]
    if full_state_size:
        rows.append({"index": N_OBS, "name": "wind_speed", "unit": "m/s", "scale": 1.0,
                     "meaning": "episode mean wind speed (privileged)", "low": 0.0,
                     "high": FULL_STATE_LIMIT})
        rows.append({"index": f"{N_OBS + 1}..{N_OBS + full_state_size}", "name": "state",
                     "unit": "SI", "scale": 1.0, "low": -FULL_STATE_LIMIT,
                     "high": FULL_STATE_LIMIT,
                     "meaning": "simulator state minus trim (StateLayout order; yaw wrapped)"})
    return rows


def bounds(full_state_size: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """float32 (low, high) of the observation space."""
    lo = [c.low for c in CHANNELS]
    hi = [c.high for c in CHANNELS]
    if full_state_size:
        lo += [0.0] + [-FULL_STATE_LIMIT] * full_state_size
        hi += [FULL_STATE_LIMIT] * (1 + full_state_size)
    return np.array(lo, dtype=np.float32), np.array(hi, dtype=np.float32)


def scales() -> np.ndarray:
    return np.array([c.scale for c in CHANNELS])


def weights_vector(weights: dict | None) -> np.ndarray:
    """Reward weights in REWARD_TERMS order; unknown names or negative/non-finite values raise."""
    w = dict(DEFAULT_WEIGHTS)
    for k, v in (weights or {}).items():
        if k not in w:
            raise ValueError(f"unknown reward weight {k!r}; known: {list(REWARD_TERMS)}")
        if not (isinstance(v, (int, float)) and np.isfinite(v) and v >= 0):
            raise ValueError(f"reward weight {k!r} must be a finite number >= 0, got {v!r}")
        w[k] = float(v)
    return np.array([w[k] for k in REWARD_TERMS])
