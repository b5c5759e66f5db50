"""Policies with Stable-Baselines3's ``predict(observation, state, episode_start,
deterministic)`` signature, so one evaluator runs baselines and trained models alike.

- :class:`PassivePolicy`: action 0, which engages the winch brake (the paper's fixed tether).
- :class:`TensionFeedbackPolicy`: a compliant winch, reeling out when the tension exceeds its
  trim value and back in slowly toward the trim length.
- :class:`aerostat_gym.agents.lqr.LQRPolicy`: gain-scheduled LQR on the linear model
  (privileged full state).
- :class:`SB3Policy`: a trained model with its VecNormalize statistics.
"""

from __future__ import annotations

import zipfile
from pathlib import Path

import numpy as np

from ..envs.spaces import CHANNELS, N_OBS

BASELINES = ("passive", "tension", "lqr")
_I_DTENSION = 13  # observation channel of the tension deviation (scale 1 kN)
_I_DLENGTH = 14  # observation channel of the length deviation (scale 10 m)


class PolicyError(ValueError):
    """A policy that cannot be loaded or does not fit the environment (clear message)."""


def _batch(obs) -> tuple[np.ndarray, bool]:
    obs = np.asarray(obs, dtype=np.float32)
    return (obs[None, :], True) if obs.ndim == 1 else (obs, False)


def _out(actions: np.ndarray, single: bool) -> np.ndarray:
    a = np.clip(actions, -1.0, 1.0).astype(np.float32).reshape(-1, 1)
    return a[0] if single else a


class PassivePolicy:
    """The braked winch: action 0 (below the brake dead band)."""

    obs_dim = N_OBS

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        obs, single = _batch(observation)
        return _out(np.zeros(len(obs)), single), state


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
        obs, single = _batch(observation)
        dT_kN = obs[:, _I_DTENSION] * CHANNELS[_I_DTENSION].scale / 1.0e3
        dL = obs[:, _I_DLENGTH] * CHANNELS[_I_DLENGTH].scale
        v = self.gain * dT_kN - dL / self.restore_time
        return _out(v / self.max_speed, single), state


class SB3Policy:
    """A Stable-Baselines3 model and (optionally) the VecNormalize whose statistics it was
    trained with; observations are normalised the same way before ``model.predict``."""

    def __init__(self, model, vecnormalize=None):
        from stable_baselines3.common.vec_env import VecNormalize

        self.model = model
        self.norm = vecnormalize if isinstance(vecnormalize, VecNormalize) else None
        self.obs_dim = int(model.observation_space.shape[0])

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        obs, single = _batch(observation)
        if self.norm is not None:
            obs = self.norm.normalize_obs(obs)
        a, _ = self.model.predict(obs, deterministic=deterministic)
        return _out(np.asarray(a).reshape(-1), single), state


def load_sb3(path: str | Path) -> SB3Policy:
    """Load a saved model (+ its ``_vecnormalize.pkl``); clear errors for a missing or corrupt
    file."""
    import pickle

    from stable_baselines3 import PPO, SAC, TD3

    from .train import vecnormalize_path

    path = Path(path)
    if not path.is_file():
        raise PolicyError(f"policy file not found: {path}")
    if not zipfile.is_zipfile(path):
        raise PolicyError(f"{path} is not a Stable-Baselines3 model (.zip archive): corrupt or "
                          "wrong file")
    errors = []
    for Algo in (PPO, SAC, TD3):
        try:
            model = Algo.load(str(path), device="cpu")
            break
        except Exception as exc:  # noqa: BLE001 - try the next algorithm, report all
            errors.append(f"{Algo.__name__}: {type(exc).__name__}: {exc}"[:200])
    else:
        raise PolicyError(f"cannot load {path} as a PPO, SAC or TD3 model: " + "; ".join(errors))
    norm = None
    stats = vecnormalize_path(path)
    if stats.is_file():
        with open(stats, "rb") as fh:
            norm = pickle.load(fh)
        norm.training = False
    shape = model.observation_space.shape
    if len(shape) != 1 or shape[0] < N_OBS:
        raise PolicyError(f"{path} was trained on observations of shape {shape}; "
                          f"TetheredAerostat-v0 gives ({N_OBS},) (standard) or the full layout")
    return SB3Policy(model, norm)


def load_policy(name: str, params=None, dt: float = 0.2):
    """A baseline by name ('passive', 'tension', 'lqr') or a saved SB3 model (path to .zip)."""
    if name == "passive":
        return PassivePolicy()
    if name == "tension":
        return TensionFeedbackPolicy()
    if name == "lqr":
        from ..params import load_params
        from .lqr import LQRPolicy

        return LQRPolicy(params or load_params(), dt=dt)
    if name.endswith(".zip") or Path(name).exists():
        return load_sb3(name)
    raise PolicyError(f"unknown policy {name!r}: use one of {BASELINES} or a path to a .zip")
