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
- :func:`aerostat_gym.agents.sb3io.combine_residual`: the combination, shared by training and
  :class:`aerostat_gym.agents.sb3io.SB3Policy` at evaluation; an optional ``deadband`` (a
  fraction of the winch's top speed) zeroes, and so brakes, every smaller command.
"""

from __future__ import annotations

import math

import numpy as np

from ..envs.spaces import N_OBS
from .sb3io import PolicyError, apply_deadband, combine_residual

#: Baselines that read the standard observation only, allowed as residual bases.
RESIDUAL_BASES = ("lqg", "modal_lqg", "tension")
#: Baselines that read the privileged full state: refused.
PRIVILEGED_BASES = ("lqr", "modal")


def check_residual(spec) -> dict:
    """The residual block {base, scale[, deadband]} validated (a clear PolicyError otherwise);
    the deadband is returned only when it is set."""
    if not isinstance(spec, dict) or set(spec) - {"base", "scale", "deadband"} \
            or "base" not in spec:
        raise PolicyError("residual must be a mapping {base: NAME, scale: S[, deadband: D]}, "
                          f"got {spec!r}")
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
    out = {"base": base, "scale": float(scale)}
    if "deadband" in spec:
        out["deadband"] = check_deadband(spec["deadband"])
    return out


def check_deadband(d) -> float:
    """A deadband: a fraction of the winch's top speed in [0, 1)."""
    if isinstance(d, bool) or not isinstance(d, (int, float)) or not math.isfinite(d) \
            or not 0 <= d < 1:
        raise PolicyError(f"residual deadband is a fraction of the winch's top speed in [0, 1), "
                          f"got {d!r}")
    return float(d)


def residual_vec_env(venv, base, scale: float, deadband: float = 0.0):
    """``venv`` (a raw SB3 VecEnv giving the standard observation first) with the actions
    made residual on ``base`` (a policy with the SB3 ``predict`` signature)."""
    from stable_baselines3.common.vec_env import VecEnvWrapper

    class ResidualVecEnv(VecEnvWrapper):
        """Adds the base policy's action: env action = clip(base + scale * action, -1, 1)."""

        def __init__(self):
            super().__init__(venv)
            self.base, self.scale, self.deadband = base, float(scale), float(deadband)
            self._obs, self._state = None, None
            self._start = np.ones(self.num_envs, bool)

        def reset(self):
            self._obs = self.venv.reset()
            self._state, self._start = None, np.ones(self.num_envs, bool)
            return self._obs

        def step_async(self, actions):
            b, self._state = self.base.predict(self._obs[:, :N_OBS], state=self._state,
                                               episode_start=self._start, deterministic=True)
            self.venv.step_async(combine_residual(b, actions, self.scale, self.deadband))

        def step_wait(self):
            obs, rew, dones, infos = self.venv.step_wait()
            self._obs, self._start = obs, np.asarray(dones, bool).copy()
            return obs, rew, dones, infos

    return ResidualVecEnv()


class DeadbandPolicy:
    """Any policy with its commands below ``deadband`` (a fraction of the winch's top speed) set
    to zero, which brakes the drum: the deadband of the residual block applied after the fact,
    to a baseline or a trained model, for studies of what it buys (``scripts/deadband_study.py``).
    """

    def __init__(self, policy, deadband: float):
        self.policy, self.deadband = policy, check_deadband(deadband)
        self.obs_dim = getattr(policy, "obs_dim", None)

    def predict(self, observation, state=None, episode_start=None, deterministic: bool = True):
        a, state = self.policy.predict(observation, state=state, episode_start=episode_start,
                                       deterministic=deterministic)
        return apply_deadband(a, self.deadband), state
