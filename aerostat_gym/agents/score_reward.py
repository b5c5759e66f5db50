"""Training on the evaluator's score: each episode's rewards divided by the braked winch's return
on the same episode.

The evaluator scores an episode as its return over the absolute passive return of its cell, so
that every scenario counts alike in the aggregate: a 1 m calm swing (passive return about -1)
as much as a 16 m/s gust field (about -10^4). Trained on the raw return, a policy sees the
turbulent high-wind episodes only: their returns are 10^2-10^4 times the calm swings', and the
gradient ignores everything else. With ``score_reward`` the reward of every step is divided by
max(|R_b|, floor), R_b the braked winch's return from the same episode start
(:class:`aerostat_gym.envs.reference.BrakedReference`), so the training return of an episode is
its score (-1 for the passive policy). The divisor depends on the episode's exogenous draws alone
(start, parameters, wind), not on the actions, so on each episode the ordering of policies is
unchanged; across episodes, each now weighs as in the evaluator's aggregate.

``floor`` bounds the weight of an episode that the braked winch already flies almost perfectly
(a near-zero initial swing in calm air): there the sensor noise alone decides the return, and an
unbounded weight would train on noise.
"""

from __future__ import annotations

import numpy as np

from ..checks import is_finite_number
from ..envs.reference import BrakedReference
from ..envs.vector import TetheredAerostatVectorEnv
from .sb3io import PolicyError, find_in_chain

#: Default floor of the reference return [return units]: about the braked winch's return of a
#: 1 m calm along-wind swing over a 120 s episode (measured on the baseline: -1.40 / -0.92 /
#: -0.56 / -0.46 at 3 / 5 / 10 / 15 m/s; the 10 m swing's are 100 times those). An episode the
#: braked winch flies better than that is weighted as such a swing.
DEFAULT_FLOOR = 0.5
SCORE_REWARD_KEYS = frozenset({"floor"})


def check_score_reward(spec) -> dict | None:
    """The validated ``score_reward`` option: ``true`` (default floor), ``false``/absent (None)
    or ``{floor: F}`` with F > 0; anything else is a PolicyError naming it."""
    if spec is None or spec is False:
        return None
    if spec is True:
        return {"floor": DEFAULT_FLOOR}
    if not isinstance(spec, dict) or set(spec) - SCORE_REWARD_KEYS:
        raise PolicyError(f"score_reward must be true, false or {{floor: F}}, got {spec!r}")
    floor = spec.get("floor", DEFAULT_FLOOR)
    if not (is_finite_number(floor) and floor > 0):
        raise PolicyError(f"score_reward floor must be a finite number > 0, got {floor!r}")
    return {"floor": float(floor)}


def native_vector_env(venv):
    """The package's native vector environment under a chain of SB3 wrappers (it holds the
    batch); a PolicyError if the chain has none."""
    native = find_in_chain(venv, TetheredAerostatVectorEnv)
    if native is not None:
        return native
    raise PolicyError("score_reward needs the package's native vector environment "
                      "(aerostat_gym.envs.sb3.sb3_vec_env)")


def score_reward_vec_env(venv, spec: dict):
    """``venv`` (an SB3 VecEnv over the native batch) with every reward divided by its
    episode's max(|braked-winch return|, floor); each episode info gets ``braked_return``."""
    from stable_baselines3.common.vec_env import VecEnvWrapper

    native = native_vector_env(venv)
    reference = BrakedReference(native.batch, native.max_episode_steps)
    floor = spec["floor"]

    class ScoreRewardVecEnv(VecEnvWrapper):
        """Rewards in score units: divided by the episode's braked-winch return."""

        def __init__(self):
            super().__init__(venv)
            self.divisor = np.ones(self.num_envs)
            self.braked = np.zeros(self.num_envs)

        def _start(self, slots) -> None:
            self.braked[slots] = reference.returns(slots)
            self.divisor[slots] = np.maximum(np.abs(self.braked[slots]), floor)

        def reset(self):
            obs = self.venv.reset()
            self._start(np.arange(self.num_envs))
            return obs

        def step_wait(self):
            obs, rew, dones, infos = self.venv.step_wait()
            rew = (rew / self.divisor).astype(np.float32)
            ended = np.flatnonzero(dones)
            for i in ended:
                infos[i]["braked_return"] = float(self.braked[i])
            if ended.size:  # same-step autoreset: these slots hold their next episode's start
                self._start(ended)
            return obs, rew, dones, infos

    return ScoreRewardVecEnv()
