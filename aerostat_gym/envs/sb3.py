"""Stable-Baselines3 adapter: the native batch as an SB3 ``VecEnv`` (no subprocesses)."""

from __future__ import annotations

import numpy as np

from .vector import TetheredAerostatVectorEnv


def sb3_vec_env(num_envs: int, seed: int | None = None, **kwargs):
    """A Stable-Baselines3 ``VecEnv`` over one compiled batch of ``num_envs`` environments."""
    from stable_baselines3.common.vec_env import VecEnv

    class SB3VecEnv(VecEnv):
        """SB3 adapter: same-step autoreset, ``terminal_observation`` and
        ``TimeLimit.truncated`` in the per-environment infos."""

        def __init__(self):
            self.venv = TetheredAerostatVectorEnv(num_envs, autoreset_mode="SameStep", **kwargs)
            self.render_mode = None
            super().__init__(num_envs, self.venv.single_observation_space,
                             self.venv.single_action_space)
            self._actions = None
            if seed is not None:
                self.seed(seed)

        def reset(self):
            seeds = self._seeds if any(s is not None for s in self._seeds) else None
            obs, info = self.venv.reset(seed=seeds)
            self._seeds = [None] * self.num_envs
            self.reset_infos = [{} for _ in range(self.num_envs)]
            return obs

        def step_async(self, actions):
            self._actions = actions

        def step_wait(self):
            obs, rew, term, trunc, info = self.venv.step(self._actions)
            dones = term | trunc
            infos = [{} for _ in range(self.num_envs)]
            if dones.any():
                for i in np.flatnonzero(dones):
                    infos[i]["terminal_observation"] = info["final_obs"][i]
                    infos[i]["TimeLimit.truncated"] = bool(trunc[i] and not term[i])
                    for key in ("termination", "failure", "truncation"):
                        if key in info and info["_" + key][i]:
                            infos[i][key] = info[key][i]
            return obs, rew.astype(np.float32), dones, infos

        def close(self):
            self.venv.close()

        def get_attr(self, attr_name, indices=None):
            return [getattr(self.venv, attr_name, None) for _ in self._get_indices(indices)]

        def set_attr(self, attr_name, value, indices=None):
            setattr(self.venv, attr_name, value)

        def env_method(self, method_name, *args, indices=None, **kw):
            return [getattr(self.venv, method_name)(*args, **kw)
                    for _ in self._get_indices(indices)]

        def env_is_wrapped(self, wrapper_class, indices=None):
            return [False for _ in self._get_indices(indices)]

    return SB3VecEnv()
