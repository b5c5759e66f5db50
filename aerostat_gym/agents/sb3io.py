"""Stable-Baselines3 input and output: saving and loading trained models with their
VecNormalize statistics, and the :class:`SB3Policy` that runs one like a baseline.

Stable-Baselines3 is an optional dependency (the ``train`` extra): it is imported inside the
functions that need it.
"""

from __future__ import annotations

import pickle
import warnings
import zipfile
from pathlib import Path

import numpy as np

from ..envs.spaces import N_OBS

VECNORM_SUFFIX = "_vecnormalize.pkl"


class PolicyError(ValueError):
    """A policy that cannot be loaded or does not fit the environment (clear message)."""


def as_batch(obs) -> tuple[np.ndarray, bool]:
    """Observations as a float32 batch, and whether a single observation was given."""
    obs = np.asarray(obs, dtype=np.float32)
    return (obs[None, :], True) if obs.ndim == 1 else (obs, False)


def to_actions(actions: np.ndarray, single: bool) -> np.ndarray:
    """Actions clipped to [-1, 1] as float32, shape (1,) or (N, 1)."""
    a = np.clip(actions, -1.0, 1.0).astype(np.float32).reshape(-1, 1)
    return a[0] if single else a


def vecnormalize_path(model_path: Path) -> Path:
    """Where the VecNormalize statistics of a saved model live: checkpoints use SB3's
    ``<prefix>_vecnormalize_<steps>_steps.pkl``; our models ``<stem>_vecnormalize.pkl``."""
    model_path = Path(model_path)
    stem = model_path.stem
    if stem.endswith("_steps") and "_" in stem:
        prefix, steps = stem.rsplit("_", 2)[0], stem.rsplit("_", 2)[1]
        return model_path.with_name(f"{prefix}_vecnormalize_{steps}_steps.pkl")
    return model_path.with_name(stem + VECNORM_SUFFIX)


def save_model(model, path: Path) -> None:
    """Save the model and, if it trains on a VecNormalize, its statistics beside it."""
    from stable_baselines3.common.vec_env import VecNormalize

    model.save(str(path))
    env = model.get_env()
    if isinstance(env, VecNormalize):
        env.save(str(vecnormalize_path(path)))


class SB3Policy:
    """A Stable-Baselines3 model and (optionally) the VecNormalize whose statistics it was
    trained with; observations are normalised the same way before ``model.predict``."""

    def __init__(self, model, vecnormalize=None):
        from stable_baselines3.common.vec_env import VecNormalize

        self.model = model
        self.norm = vecnormalize if isinstance(vecnormalize, VecNormalize) else None
        self.obs_dim = int(model.observation_space.shape[0])

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        obs, single = as_batch(observation)
        if self.norm is not None:
            obs = self.norm.normalize_obs(obs)
        a, _ = self.model.predict(obs, deterministic=deterministic)
        return to_actions(np.asarray(a).reshape(-1), single), state


def load_sb3(path: str | Path) -> SB3Policy:
    """Load a saved model (+ its ``_vecnormalize.pkl``); clear errors for a missing or corrupt
    file."""
    from stable_baselines3 import PPO, SAC, TD3

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
    else:
        warnings.warn(f"no VecNormalize statistics beside {path} (looked for {stats.name}): the "
                      "policy sees raw observations, which is wrong if it was trained with "
                      "normalisation", stacklevel=2)
    shape = model.observation_space.shape
    if len(shape) != 1 or shape[0] < N_OBS:
        raise PolicyError(f"{path} was trained on observations of shape {shape}; "
                          f"TetheredAerostat-v0 gives ({N_OBS},) (standard) or the full layout")
    return SB3Policy(model, norm)
