"""Policies with Stable-Baselines3's ``predict(observation, state, episode_start,
deterministic)`` signature, so one evaluator runs baselines and trained models alike.

- :class:`PassivePolicy`: action 0, which engages the winch brake (the paper's fixed tether).
- :class:`TensionFeedbackPolicy`: a compliant winch, reeling out when the tension exceeds its
  trim value and back in slowly toward the trim length.
- :class:`aerostat_gym.agents.lqr.LQRPolicy`: gain-scheduled LQR on the linear model
  (privileged full state).
- :class:`aerostat_gym.agents.sb3io.SB3Policy`: a trained model with its VecNormalize
  statistics.

:func:`load_policy` resolves a name or a path to one of them.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..envs.spaces import CHANNELS, N_OBS, OBS_DLENGTH, OBS_DTENSION
from ..params import load_params
from ..resources import SHIPPED_POLICY, shipped_path
from .lqr import LQRPolicy
from .sb3io import PolicyError, as_batch, load_sb3, to_actions

BASELINES = ("passive", "tension", "lqr")
#: Names of trained policies that ship with the package.
SHIPPED = {"shipped": SHIPPED_POLICY}


class PassivePolicy:
    """The braked winch: action 0 (below the brake dead band)."""

    obs_dim = N_OBS

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        obs, single = as_batch(observation)
        return to_actions(np.zeros(len(obs)), single), state


class TensionFeedbackPolicy:
    """Compliant winch: v = k_T (T - T_trim) - (L - L_trim) / tau_L, clipped to the winch limit.

    Parameters
    ----------
    gain : reel-out speed per tension excess [m/s per kN] (default 0.3).
    restore_time : time constant of the length-restoring term [s] (default 60).
    max_speed : winch speed limit [m/s] the action is a fraction of (default 1).
    """

    obs_dim = N_OBS

    def __init__(self, gain: float = 0.3, restore_time: float = 60.0, max_speed: float = 1.0):
        if not (gain >= 0 and restore_time > 0 and max_speed > 0):
            raise ValueError("tension feedback needs gain >= 0, restore_time > 0, max_speed > 0")
        self.gain, self.restore_time, self.max_speed = gain, restore_time, max_speed

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        obs, single = as_batch(observation)
        dT_kN = obs[:, OBS_DTENSION] * CHANNELS[OBS_DTENSION].scale / 1.0e3
        dL = obs[:, OBS_DLENGTH] * CHANNELS[OBS_DLENGTH].scale
        v = self.gain * dT_kN - dL / self.restore_time
        return to_actions(v / self.max_speed, single), state


def load_policy(name: str, params=None, dt: float = 0.2):
    """A baseline by name ('passive', 'tension', 'lqr'), a shipped trained policy by name
    ('shipped': the package's default PPO policy) or a saved SB3 model (path to .zip)."""
    if name == "passive":
        return PassivePolicy()
    if name == "tension":
        return TensionFeedbackPolicy()
    if name == "lqr":
        return LQRPolicy(params or load_params(), dt=dt)
    if name in SHIPPED:
        return load_sb3(shipped_path(SHIPPED[name]))
    if name.endswith(".zip") or Path(name).exists():
        return load_sb3(name)
    raise PolicyError(f"unknown policy {name!r}: use one of {BASELINES + tuple(SHIPPED)} or a "
                      "path to a .zip")
