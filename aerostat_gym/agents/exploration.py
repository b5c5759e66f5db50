"""How much of a residual policy's exploration reaches the winch.

PPO learns from the difference its sampled actions make. A residual's sample a = mu + sigma e
(e standard normal) passes the command path (:class:`~aerostat_gym.agents.sb3io.CommandShaper`)
before it moves the drum: times the residual's scale, through the low-pass, then the deadband,
which brakes every filtered command under it. With the shipped configuration (scale 0.1,
low-pass 1 s at 0.2 s steps, deadband 0.03 of the top speed) and the action spread PPO ends with
(sigma about 0.13), the set-point moves by about 0.004 of the top speed on the exploration alone:
an eighth of the deadband, so wherever the base's own command lies under the deadband the
exploration changes nothing at all.

- :func:`lowpass_noise_gain`: the closed form, the stationary standard deviation of the
  low-pass output per unit of white input, sqrt(alpha / (2 - alpha)).
- :func:`exploration_reach`: the measured version on a recorded episode. The command path runs
  twice over the same base commands and policy means, once with the means (the deterministic
  path that was flown) and once with sampled actions; the result is the share of steps at
  which the set-point sent to the winch differs and the RMS of the difference, in units of the
  winch's top speed. Feeding both paths the same inputs leaves out the feedback of a changed
  command on later states: it measures what the sampling itself puts through, not where it
  would have flown.
"""

from __future__ import annotations

import math

import numpy as np

from .sb3io import CommandShaper


def lowpass_noise_gain(alpha: float) -> float:
    """Stationary std of y <- y + alpha (u - y) per unit std of a white input u: the AR(1)
    variance alpha^2 / (1 - (1 - alpha)^2) = alpha / (2 - alpha), square-rooted."""
    if not (0.0 < alpha <= 1.0):
        raise ValueError(f"alpha is a low-pass gain in (0, 1], got {alpha!r}")
    return math.sqrt(alpha / (2.0 - alpha))


def exploration_reach(shaper: CommandShaper, base: np.ndarray, mean: np.ndarray,
                      sigma: float, rng: np.random.Generator) -> dict:
    """What the sampling puts through ``shaper`` on one recorded episode.

    ``base``, ``mean``: (T,) the base controller's command and the policy's mean action at
    each step (in action units, [-1, 1]); ``sigma``: the policy's action standard deviation.
    The sampled action is clipped to [-1, 1] as SB3 clips it for a Box space. Returns
    {"changed": share of steps whose set-point differs, "rms": RMS set-point difference,
    "rms_mean_command": RMS of the deterministic set-point}, the last two in top speeds.
    """
    base = np.asarray(base, np.float64).reshape(-1)
    mean = np.asarray(mean, np.float64).reshape(-1)
    if base.shape != mean.shape or base.size == 0:
        raise ValueError(f"base and mean must be equal-length episodes, got {base.shape} and "
                         f"{mean.shape}")
    if not (math.isfinite(sigma) and sigma >= 0.0):
        raise ValueError(f"sigma must be a finite standard deviation >= 0, got {sigma!r}")
    sampled = np.clip(mean + sigma * rng.standard_normal(mean.size), -1.0, 1.0)
    flown, tried = _run(shaper, base, mean), _run(shaper, base, sampled)
    diff = tried - flown
    return {"changed": float(np.mean(diff != 0.0)), "rms": float(np.sqrt(np.mean(diff ** 2))),
            "rms_mean_command": float(np.sqrt(np.mean(flown ** 2)))}


def _run(shaper: CommandShaper, base: np.ndarray, action: np.ndarray) -> np.ndarray:
    """The set-points of one episode through the command path, its filter starting at rest."""
    out, state = np.empty(base.size), None
    for k in range(base.size):
        c, state = shaper(base[k:k + 1], action[k:k + 1], state, np.array([k == 0]))
        out[k] = c[0, 0]
    return out
