"""The environment's observation table, reward terms and termination codes, written down once.

Every observation channel is a physical quantity divided by its scale, clipped to finite bounds.
Frames and signs (as everywhere in the package, see the README): inertial X, Y, Z with Z up and
the winch at the origin; the default wind blows along +X; attitude is the Z-Y-X Euler triple
(roll phi, pitch theta, yaw psi; theta < 0 is nose up, so a positive pitch channel is nose
down; at trim psi = pi, the nose into the wind);
body rates p, q, r about the body x (nose), y and z axes; a positive reel speed pays line out.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..checks import is_finite_number
from ..params.steps import SEMI_IMPLICIT_REFERENCE_HULL_LENGTH

#: The tether length [m] the task's sizes are stated for (the baseline's 300 m): the
#: perturbation presets' displacements (:data:`aerostat_gym.envs.config.PERTURBATIONS`), the
#: evaluator's recover swings, and the reward's swing terms (:func:`aerostat_gym.envs.reward.
#: sized_weights`). On another tether they scale with its length, so that every aerostat is
#: swung through the same angle about the winch (10 m on 300 m: 1.9 degrees, where 10 m on a
#: 30 m tether would be 19 degrees, far outside the linear regime the task's controllers and
#: the evaluator's fits assume) and scores it as the baseline does. The channels' scales below
#: stay the baseline's on every aerostat.
REFERENCE_TETHER_LENGTH = 300.0
#: The hull length [m] the body-rate limits are stated for (the baseline's; see SIZED_CHANNELS).
REFERENCE_HULL_LENGTH = SEMI_IMPLICIT_REFERENCE_HULL_LENGTH
#: Body-rate clip limit [rad/s] on the reference hull.
RATE_LIMIT = 2.0


def displacement_scale(tether_length: float | None) -> float:
    """Factor on stated displacements for a tether of ``tether_length`` [m] (None: the
    reference, factor 1): ``tether_length`` / :data:`REFERENCE_TETHER_LENGTH`."""
    return 1.0 if tether_length is None else float(tether_length) / REFERENCE_TETHER_LENGTH


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
    _ch("dpitch", "pitch theta minus trim (theta < 0 is nose up: positive is nose down)", "rad",
        0.05, np.pi),
    _ch("dyaw", "yaw psi minus trim, wrapped to [-pi, pi]", "rad", 0.05, np.pi),
    _ch("p", "body roll rate", "rad/s", 0.02, RATE_LIMIT),
    _ch("q", "body pitch rate", "rad/s", 0.02, RATE_LIMIT),
    _ch("r", "body yaw rate", "rad/s", 0.02, RATE_LIMIT),
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

#: Named channel indices (the position of each channel in CHANNELS; checked by the tests).
OBS_DX, OBS_DY, OBS_DZ = 0, 1, 2
OBS_VX, OBS_VY, OBS_VZ = 3, 4, 5
OBS_DROLL, OBS_DPITCH, OBS_DYAW = 6, 7, 8
OBS_P, OBS_Q, OBS_R = 9, 10, 11
OBS_TENSION, OBS_DTENSION = 12, 13
OBS_DLENGTH, OBS_REEL_SPEED = 14, 15
OBS_WIND_X, OBS_WIND_Y, OBS_WIND_Z = 16, 17, 18
#: Channel index by name, e.g. ``OBS_INDEX["dpitch"] == OBS_DPITCH``.
OBS_INDEX = {c.name: i for i, c in enumerate(CHANNELS)}
#: ``observation="full"``: index of the episode's mean wind speed, then the first index of the
#: state deviation x - x_trim (StateLayout order).
OBS_FULL_WIND = N_OBS
OBS_FULL_STATE = N_OBS + 1

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


def _froude_rate_limit(params) -> float:
    """Body-rate clip limit [rad/s] for ``params``' hull: the table's, sized for the 18.3 m
    baseline, times sqrt(18.3 m / hull length)."""
    return RATE_LIMIT * math.sqrt(REFERENCE_HULL_LENGTH / params.aerostat.length)


#: Channels whose clip limit grows with the configured aerostat, and the SI limit each needs:
#: positions reach the winch's longest line, the length channel its whole range, the tension
#: channels twice the tether strength (a break is at 1x), the reel speed twice the winch's top
#: speed, and the body rates the table's 2 rad/s times sqrt(18.3 m / hull length) (Froude
#: similarity: a hull k times shorter turns sqrt(k) times faster in the same disturbance). A
#: limit never shrinks below the table's (sized for [LN02]'s baseline, whose space is
#: therefore unchanged).
SIZED_CHANNELS = {
    "dx": lambda p: p.winch.max_length,
    "dy": lambda p: p.winch.max_length,
    "dz": lambda p: p.winch.max_length,
    "dlength": lambda p: p.winch.max_length - p.winch.min_length,
    "tension": lambda p: 2.0 * p.tether.strength,
    "dtension": lambda p: 2.0 * p.tether.strength,
    "reel_speed": lambda p: 2.0 * p.winch.max_speed,
    "p": _froude_rate_limit,
    "q": _froude_rate_limit,
    "r": _froude_rate_limit,
}


def bounds(full_state_size: int = 0, params=None) -> tuple[np.ndarray, np.ndarray]:
    """float32 (low, high) of the observation space; with ``params``, the limits of
    :data:`SIZED_CHANNELS` widened to that aerostat's reach, length range and strength."""
    lo = [c.low for c in CHANNELS]
    hi = [c.high for c in CHANNELS]
    if params is not None:
        for i, c in enumerate(CHANNELS):
            if c.name in SIZED_CHANNELS:
                limit = max(c.high, SIZED_CHANNELS[c.name](params) / c.scale)
                hi[i] = limit
                lo[i] = -limit if c.low < 0.0 else c.low
    if full_state_size:
        lo += [0.0] + [-FULL_STATE_LIMIT] * full_state_size
        hi += [FULL_STATE_LIMIT] * (1 + full_state_size)
    return np.array(lo, dtype=np.float32), np.array(hi, dtype=np.float32)


def scales() -> np.ndarray:
    return np.array([c.scale for c in CHANNELS])


def _channel_name(index: int, width: int) -> str:
    """The name of entry ``index`` of an observation ``width`` channels wide: the standard
    channel's, then (the full layout) the mean wind speed and the state deviation's entries;
    a narrower vector is no layout of the task's, so its entries go by position."""
    if width < N_OBS:
        return f"channel {index}"
    if index < N_OBS:
        return CHANNELS[index].name
    if index == OBS_FULL_WIND:
        return "wind_speed"
    return f"state[{index - OBS_FULL_STATE}]"


def _refuse_non_finite(arr: np.ndarray) -> None:
    """A ValueError naming the channels of ``arr`` (last axis) that hold NaN or infinities,
    with the first such value of each and the batch rows they are in."""
    bad = ~np.isfinite(arr.reshape(-1, arr.shape[-1]) if arr.ndim else arr.reshape(1, 1))
    rows, cols = np.nonzero(bad)
    flat = arr.reshape(bad.shape)
    named = [f"{flat[rows[cols == c][0], c]} in {_channel_name(c, bad.shape[1])}"
             for c in np.unique(cols)]
    where = f" (batch rows {np.unique(rows).tolist()})" if arr.ndim > 1 else ""
    raise ValueError(f"observations must be finite: got {', '.join(named)}{where}")


def as_batch(obs, dtype=np.float32, episode_start=None) -> tuple[np.ndarray, bool]:
    """Observations as a 2-D batch of ``dtype``, and whether a single vector was given: the one
    door every policy's ``predict`` reads through. Anything that is not an array of real
    numbers, or holds NaN or infinities, is a ValueError naming what was given (the channels
    by name), raised before a policy touches its state; so is an ``episode_start`` (when given)
    that does not hold one flag per observation of the batch."""
    try:
        arr = np.asarray(obs)
        ok = arr.dtype.kind in "biuf"
    except (TypeError, ValueError):  # ragged nested lists
        ok = False
    if not ok:
        raise ValueError(f"observations must be an array of real numbers, got {obs!r:.80}")
    arr = arr.astype(dtype, copy=False)
    if arr.dtype.kind == "f" and not np.isfinite(arr).all():
        _refuse_non_finite(arr)
    batch, single = (arr[None, :], True) if arr.ndim == 1 else (arr, False)
    if episode_start is not None:
        _check_episode_start(episode_start, len(batch) if batch.ndim else 1)
    return batch, single


def _check_episode_start(episode_start, n: int) -> None:
    """``episode_start``: one boolean flag per observation of a batch of ``n``."""
    try:
        flags = np.asarray(episode_start)
        ok = flags.dtype.kind in "biuf"  # RecurrentPPO keeps its flags as floats
    except (TypeError, ValueError):
        ok = False
    if not ok:
        raise ValueError(f"episode_start must be flags (booleans), one per observation, got "
                         f"{episode_start!r:.80}")
    if flags.size != n:
        raise ValueError(f"episode_start must hold one flag per observation of the batch ({n}), "
                         f"got {flags.size}")


def check_obs_noise(value, error: type[ValueError] = ValueError) -> float:
    """A sensor-noise level (the standard deviation added to every standard channel, in scaled
    units) as a float: a finite real number >= 0, else ``error`` naming the value. One check
    for every door that takes it (the task, the LQG design, a saved residual block)."""
    if not (is_finite_number(value) and value >= 0):
        raise error(f"obs_noise must be a finite number >= 0, got {value!r}")
    return float(value)
