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
- :class:`aerostat_gym.agents.sb3io.CommandShaper`: the command path, shared by training and
  :class:`aerostat_gym.agents.sb3io.SB3Policy` at evaluation; an optional ``lowpass`` (a time
  constant [s]) filters the summed command, an optional ``deadband`` (a fraction of the winch's
  top speed) then zeroes, and so brakes, every smaller command.
- :class:`ShapedPolicy`: the same low-pass and deadband put on any policy after the fact, for
  the studies that ask what they buy without learning.
"""

from __future__ import annotations

import numpy as np

from ..checks import is_finite_number
from ..envs.spaces import N_OBS, as_batch
from .sb3io import CommandShaper, PolicyError, check_lowpass_on
from .state_check import check_state_passed

#: Baselines that read the standard observation only, allowed as residual bases.
RESIDUAL_BASES = ("lqg", "modal_lqg", "tension")
#: Keys of a residual block.
RESIDUAL_KEYS = frozenset({"base", "scale", "deadband", "lowpass", "lowpass_on",
                           "observe_estimate", "relief"})
#: Bases with a Kalman filter, whose estimate the learned residual can be given to read.
ESTIMATE_BASES = ("lqg", "modal_lqg")
#: Baselines that read the privileged full state: refused.
PRIVILEGED_BASES = ("lqr", "modal")


#: Longest command low-pass time constant accepted [s]: about a tenth of the baseline's fastest
#: pendulum period (36 s at 15 m/s); longer filters lag the swing they are to damp.
MAX_LOWPASS = 4.0

#: Largest tension relief accepted on a residual base [winch top speeds per net lift]: at 10 the
#: winch saturates on a tension excess of a tenth of the net lift, a load-cell noise level.
MAX_RELIEF = 10.0


def check_residual(spec) -> dict:
    """The residual block {base, scale[, deadband][, lowpass][, lowpass_on][, observe_estimate]
    [, relief]} validated (a clear PolicyError otherwise); the optional keys are returned only
    when they are set."""
    if not isinstance(spec, dict) or set(spec) - RESIDUAL_KEYS or "base" not in spec:
        raise PolicyError("residual must be a mapping {base: NAME, scale: S[, deadband: D]"
                          "[, lowpass: TAU][, lowpass_on: sum|base][, observe_estimate: "
                          f"true][, relief: R]}}, got {spec!r}")
    base = spec["base"]
    if base in PRIVILEGED_BASES:
        raise PolicyError(f"residual base {base!r} reads the privileged full state: learned and "
                          "classical policies are compared on equal information, so use one of "
                          f"{RESIDUAL_BASES}")
    if base not in RESIDUAL_BASES:
        raise PolicyError(f"unknown residual base {base!r}; choose one of {RESIDUAL_BASES}")
    scale = spec.get("scale", 0.3)
    if not (is_finite_number(scale) and 0 < scale <= 2):
        raise PolicyError(f"residual scale must be a number in (0, 2], got {scale!r}")
    out = {"base": base, "scale": float(scale)}
    if "deadband" in spec:
        out["deadband"] = check_deadband(spec["deadband"])
    if "lowpass" in spec:
        out["lowpass"] = check_lowpass(spec["lowpass"])
    if "lowpass_on" in spec:
        out["lowpass_on"] = check_lowpass_on(spec["lowpass_on"])
    if spec.get("observe_estimate", False) is not False:
        out["observe_estimate"] = check_observe_estimate(spec["observe_estimate"], base)
    if spec.get("relief", 0) != 0:
        out["relief"] = check_relief(spec["relief"], out.get("observe_estimate", False))
    return out


def check_relief(relief, observe_estimate: bool) -> float:
    """A tension relief on the base (:class:`aerostat_gym.agents.policies.TensionRelief`): a gain
    in (0, MAX_RELIEF] winch top speeds per net lift. The relieved base has no filter estimate of
    its own command, so it does not combine with ``observe_estimate``."""
    if not (is_finite_number(relief) and 0 < relief <= MAX_RELIEF):
        raise PolicyError(f"residual relief is a gain in (0, {MAX_RELIEF:g}] winch top speeds "
                          f"per net lift of tension above trim, got {relief!r}")
    if observe_estimate:
        raise PolicyError("residual relief and observe_estimate do not combine: the estimate "
                          "features carry the Kalman-filter base's command, not the relieved one")
    return float(relief)


def check_observe_estimate(flag, base: str) -> bool:
    """``observe_estimate: true``: the policy also reads the base's filter estimate, which only
    the Kalman-filter bases (:data:`ESTIMATE_BASES`) have."""
    if not isinstance(flag, bool):
        raise PolicyError(f"residual observe_estimate must be true or false, got {flag!r}")
    if base not in ESTIMATE_BASES:
        raise PolicyError(f"residual observe_estimate needs a base with a Kalman filter "
                          f"{ESTIMATE_BASES}; {base!r} has none")
    return True


def check_lowpass(tau) -> float:
    """A command low-pass time constant [s] in [0, MAX_LOWPASS] (0: no filter)."""
    if not (is_finite_number(tau) and 0 <= tau <= MAX_LOWPASS):
        raise PolicyError(f"residual lowpass is a time constant in [0, {MAX_LOWPASS:g}] s, "
                          f"got {tau!r}")
    return float(tau)


def residual_shaper(spec: dict, dt: float) -> CommandShaper:
    """The command path of a validated residual block at control step ``dt`` [s]."""
    return CommandShaper(spec["scale"], spec.get("deadband", 0.0), spec.get("lowpass", 0.0), dt,
                         spec.get("lowpass_on", "sum"))


def check_deadband(d) -> float:
    """A deadband: a fraction of the winch's top speed in [0, 1)."""
    if not (is_finite_number(d) and 0 <= d < 1):
        raise PolicyError(f"residual deadband is a fraction of the winch's top speed in [0, 1), "
                          f"got {d!r}")
    return float(d)


def residual_vec_env(venv, base, shaper: CommandShaper, observe_estimate: bool = False):
    """``venv`` (a raw SB3 VecEnv giving the standard observation first) with the actions
    made residual on ``base`` (a policy with the SB3 ``predict`` signature) through ``shaper``;
    with ``observe_estimate`` the observation also carries the base's filter estimate
    (:meth:`aerostat_gym.agents.lqg.LQGPolicy.estimate_features`) after the environment's
    channels."""
    from gymnasium import spaces
    from stable_baselines3.common.vec_env import VecEnvWrapper

    class ResidualVecEnv(VecEnvWrapper):
        """Adds the base policy's action: env action = shaper(base, action). The base reads
        each observation as it arrives, so its command (and estimate) for that step is ready
        when the policy acts on it."""

        def __init__(self):
            space = venv.observation_space
            if observe_estimate:
                n = base.n_features
                space = spaces.Box(np.append(space.low, np.full(n, -np.inf, np.float32)),
                                   np.append(space.high, np.full(n, np.inf, np.float32)),
                                   dtype=np.float32)
            super().__init__(venv, observation_space=space)
            self.base, self.shaper = base, shaper
            self._command, self._state, self._filter = None, None, None
            self._start = np.ones(self.num_envs, bool)

        def _read(self, obs):
            """The base's command for ``obs``; the observation the policy reads."""
            self._command, self._state = self.base.predict(
                obs[:, :N_OBS], state=self._state, episode_start=self._start,
                deterministic=True)
            if not observe_estimate:
                return obs
            return np.hstack([obs, self.base.estimate_features(self._state)])

        def reset(self):
            self._state, self._filter = None, None
            self._start = np.ones(self.num_envs, bool)
            return self._read(self.venv.reset())

        def step_async(self, actions):
            cmd, self._filter = self.shaper(self._command, actions, self._filter, self._start)
            self.venv.step_async(cmd)

        def step_wait(self):
            obs, rew, dones, infos = self.venv.step_wait()
            if observe_estimate:
                self._terminal_features(np.flatnonzero(dones), infos)
            self._start = np.asarray(dones, bool).copy()
            return self._read(obs), rew, dones, infos

        def _terminal_features(self, ended, infos):
            """The estimate after each ended episode's last observation (what the value of a
            truncated episode is bootstrapped from), on a copy of the base's state."""
            ended = [i for i in ended if "terminal_observation" in infos[i]]
            if not ended:
                return
            last = np.array([infos[i]["terminal_observation"] for i in ended])
            _, state = self.base.predict(last[:, :N_OBS], state=self._state[ended],
                                         episode_start=self._start[ended], deterministic=True)
            features = self.base.estimate_features(state)
            for k, i in enumerate(ended):
                infos[i]["terminal_observation"] = np.append(last[k], features[k])

    return ResidualVecEnv()


class ShapedPolicy:
    """Any policy with the residual's low-pass (time constant ``lowpass`` [s] at control step
    ``dt``) and ``deadband`` (a fraction of the winch's top speed; smaller commands brake) put on
    its commands after the fact: :class:`CommandShaper` with a zero residual. For the studies
    of what the command path buys without learning (``scripts/deadband_study.py``)."""

    def __init__(self, policy, deadband: float = 0.0, lowpass: float = 0.0, dt: float = 0.2):
        self.policy = policy
        self.shaper = CommandShaper(1.0, check_deadband(deadband), check_lowpass(lowpass), dt)
        self.obs_dim = getattr(policy, "obs_dim", None)

    def predict(self, observation, state=None, episode_start=None, deterministic: bool = True):
        obs, single = as_batch(observation, episode_start=episode_start)
        check_state_passed(self, state, episode_start, len(obs), "the command low-pass and "
                           "the inner policy's state")
        state = state if isinstance(state, dict) else {}
        a, inner = self.policy.predict(observation, state=state.get("inner"),
                                       episode_start=episode_start, deterministic=deterministic)
        a = np.asarray(a, np.float64).reshape(-1)
        start = None if episode_start is None else np.asarray(episode_start, bool).reshape(-1)
        cmd, filtered = self.shaper(a, np.zeros_like(a), state.get("filter"), start)
        return (cmd[0] if single else cmd), {"inner": inner, "filter": filtered}
