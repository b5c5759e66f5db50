"""Residual learning on a classical winch controller: the action sent to the environment is
clip(base_action + scale * policy_action, -1, 1), where the base policy is a baseline that reads
the standard observation (:data:`RESIDUAL_BASES`) and keeps its own state across steps.

Learned and classical policies are compared on equal information, so the privileged baselines
(LQR and modal pole placement read the full state) are refused as bases; their output-feedback
forms (``lqg``, ``modal_lqg``: the same gains on a Kalman filter's estimate) are allowed.

- :func:`check_residual`: the validated ``residual`` block of a training configuration.
- :func:`residual_vec_env`: the SB3 ``VecEnvWrapper`` that applies the base policy during
  training; it sits on the raw environment (below VecNormalize), so the base policy reads the
  observation the environment gives, and it resets the base policy's state at every episode
  start (the batch resets an environment in the same step its episode ends).
- :func:`residual_action`: the combination, shared with :class:`aerostat_gym.agents.sb3io.SB3Policy`
  at evaluation.
"""

from __future__ import annotations

import math

import numpy as np

from ..envs.spaces import N_OBS
from .sb3io import PolicyError

#: Baselines that read the standard observation only, allowed as residual bases.
RESIDUAL_BASES = ("lqg", "modal_lqg", "tension")
#: Baselines that read the privileged full state: refused.
PRIVILEGED_BASES = ("lqr", "modal")


def check_residual(spec) -> dict:
    """The residual block {base, scale} validated (a clear PolicyError otherwise)."""
    if not isinstance(spec, dict) or set(spec) - {"base", "scale"} or "base" not in spec:
        raise PolicyError(f"residual must be a mapping {{base: NAME, scale: S}}, got {spec!r}")
    base = spec["base"]
    if base in PRIVILEGED_BASES:
        raise PolicyError(f"residual base {base!r} reads the privileged full state: learned and "
                          "classical policies are compared on equal information, so use one of "
                          f"{RESIDUAL_BASES}")
    if base not in RESIDUAL_BASES:
        raise PolicyError(f"unknown residual base {base!r}; choose one of {RESIDUAL_BASES}")
    scale = spec.get("scale", 0.3)
    if isinstance(scale, bool) or not isinstance(scale, (int, float)) \
            or not math.isfinite(scale) or not 0 < scale <= 2:
        raise PolicyError(f"residual scale must be a number in (0, 2], got {scale!r}")
    return {"base": base, "scale": float(scale)}


def residual_action(base_action, policy_action, scale: float) -> np.ndarray:
    """clip(base + scale * clip(policy, -1, 1), -1, 1) as float32, shape (N, 1)."""
    b = np.asarray(base_action, np.float64).reshape(-1)
    a = np.clip(np.asarray(policy_action, np.float64).reshape(-1), -1.0, 1.0)
    return np.clip(b + scale * a, -1.0, 1.0).astype(np.float32)[:, None]


def residual_vec_env(venv, base, scale: float):
    """``venv`` (a raw SB3 VecEnv giving the standard observation first) with the actions
    made residual on ``base`` (a policy with the SB3 ``predict`` signature)."""
    from stable_baselines3.common.vec_env import VecEnvWrapper

    class ResidualVecEnv(VecEnvWrapper):
        """Adds the base policy's action: env action = clip(base + scale * action, -1, 1)."""

        def __init__(self):
            super().__init__(venv)
            self.base, self.scale = base, float(scale)
            self._obs, self._state = None, None
            self._start = np.ones(self.num_envs, bool)

        def reset(self):
            self._obs = self.venv.reset()
            self._state, self._start = None, np.ones(self.num_envs, bool)
            return self._obs

        def step_async(self, actions):
            b, self._state = self.base.predict(self._obs[:, :N_OBS], state=self._state,
                                               episode_start=self._start, deterministic=True)
            self.venv.step_async(residual_action(b, actions, self.scale))

        def step_wait(self):
            obs, rew, dones, infos = self.venv.step_wait()
            self._obs, self._start = obs, np.asarray(dones, bool).copy()
            return obs, rew, dones, infos

    return ResidualVecEnv()
