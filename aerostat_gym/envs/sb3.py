"""Stable-Baselines3 adapter: the native batch as an SB3 ``VecEnv`` (no subprocesses)."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from ..checks import is_whole
from .vector import SB3_RESET_PREFIX, TetheredAerostatVectorEnv


def check_seed(seed) -> int | None:
    """The adapter's seed: None (unseeded) or an integer >= 0 (environment i is seeded with
    seed + i at the next reset, as SB3's ``VecEnv.seed`` does), else a ValueError naming it."""
    if seed is not None and not is_whole(seed, 0):
        raise ValueError(f"seed must be None or an integer >= 0, got {seed!r}")
    return seed


def check_set_options(options, num_envs: int) -> list[dict]:
    """SB3's ``set_options`` argument as one dict of reset options per environment: None (no
    options), one dict for every environment, or a list of ``num_envs`` dicts."""
    if options is None:
        return [{} for _ in range(num_envs)]
    if isinstance(options, Mapping):
        return [dict(options) for _ in range(num_envs)]
    if (isinstance(options, (list, tuple)) and len(options) == num_envs
            and all(isinstance(o, Mapping) for o in options)):
        return [dict(o) for o in options]
    raise ValueError(f"set_options takes a dict of reset options or a list of {num_envs} "
                     f"(one per environment), got {options!r:.80}")


def env_infos(info: dict, num_envs: int, prefix: str = "") -> list[dict]:
    """Gymnasium's stacked vector info (per key an array over environments and a ``_key``
    mask) as one dict per environment, the keys that start with ``prefix`` (stripped)."""
    out = [{} for _ in range(num_envs)]
    for key, values in info.items():
        if key.startswith("_") or not key.startswith(prefix):
            continue
        name, mask = key[len(prefix):], info["_" + key]
        if mask.all() and isinstance(values, np.ndarray):  # every step's keys: one pass
            for env_info, value in zip(out, values, strict=True):  # numpy scalars, as the env's
                env_info[name] = value
            continue
        for i in np.flatnonzero(mask):
            out[i][name] = values[i]
    return out


def step_infos(info: dict, terminated: np.ndarray, truncated: np.ndarray) -> list[dict]:
    """SB3's per-environment step infos from the native batch's SAME_STEP info, as
    ``DummyVecEnv`` over the single environment has them: every environment's step info (reward
    terms, time, peak tension, action_clipped, an end's reason) and ``TimeLimit.truncated``;
    an ended environment's step info is its ended episode's, with ``terminal_observation``."""
    n = terminated.size
    running = {k: v for k, v in info.items() if k.lstrip("_") not in ("final_info", "final_obs")}
    infos = env_infos(running, n)  # the running environments' rows are their step infos
    done = terminated | truncated
    if done.any():
        ended = env_infos(info["final_info"], n)
        for i in np.flatnonzero(done):
            infos[i] = ended[i]
            infos[i]["terminal_observation"] = info["final_obs"][i]
    for i, env_info in enumerate(infos):
        env_info["TimeLimit.truncated"] = bool(truncated[i] and not terminated[i])
    return infos


def sb3_vec_env(num_envs: int, seed: int | None = None, **kwargs):
    """A Stable-Baselines3 ``VecEnv`` over one compiled batch of ``num_envs`` environments.

    As SB3's ``DummyVecEnv``: ``seed`` (and ``seed()``) and ``set_options()`` apply at the next
    ``reset()`` only, then are cleared; ``reset_infos`` holds each environment's reset info
    (after an automatic reset inside ``step``, the new episode's)."""
    from stable_baselines3.common.vec_env import VecEnv

    check_seed(seed)

    class SB3VecEnv(VecEnv):
        """SB3 adapter: same-step autoreset, ``terminal_observation`` and
        ``TimeLimit.truncated`` in the per-environment infos."""

        def __init__(self):
            self.venv = TetheredAerostatVectorEnv(num_envs, autoreset_mode="SameStep", **kwargs)
            super().__init__(num_envs, self.venv.single_observation_space,
                             self.venv.single_action_space)
            self._actions = None
            if seed is not None:
                self.seed(seed)

        def seed(self, seed=None):
            check_seed(seed)  # at the call, as sb3_vec_env(seed=...): not at the next reset
            return super().seed(seed)

        def set_options(self, options=None) -> None:
            self._options = check_set_options(options, self.num_envs)

        def reset(self):
            if any(self._options):
                obs = self._reset_each()
            else:
                obs, info = self.venv.reset(seed=self._seeds)
                self.reset_infos = env_infos(info, self.num_envs)
            self._reset_seeds()
            self._reset_options()
            return obs

        def _reset_each(self):
            """Reset every environment with its own options (one masked reset each)."""
            obs = None
            for i, opts in enumerate(self._options):
                mask = np.arange(self.num_envs) == i
                obs, info = self.venv.reset(seed=self._seeds,
                                            options={**opts, "reset_mask": mask})
                self.reset_infos[i] = env_infos(info, self.num_envs)[i]
            return obs

        def step_async(self, actions):
            self._actions = actions

        def step_wait(self):
            obs, rew, term, trunc, info = self.venv.step(self._actions)
            dones = term | trunc
            infos = step_infos(info, term, trunc)
            if dones.any():
                started = env_infos(info, self.num_envs, prefix=SB3_RESET_PREFIX)
                for i in np.flatnonzero(dones):
                    self.reset_infos[i] = started[i]
            return obs, rew.astype(np.float32), dones, infos

        def get_images(self):
            """One rgb_array frame per environment (``render_mode="rgb_array"``)."""
            frames = self.venv.render()
            return [None] * self.num_envs if frames is None else list(frames)

        def close(self):
            self.venv.close()

        def get_attr(self, attr_name, indices=None):
            """The batch's attribute, once per index: the environments share one batch and
            one value (an unknown name is an AttributeError naming it, as DummyVecEnv's)."""
            value = getattr(self.venv, attr_name)
            return [value for _ in self._get_indices(indices)]

        def set_attr(self, attr_name, value, indices=None):
            """Set an attribute of the shared batch: only for all environments at once."""
            if sorted(self._get_indices(indices)) != list(range(self.num_envs)):
                raise ValueError(f"set_attr({attr_name!r}, indices={indices!r}): the "
                                 "environments of sb3_vec_env share one batch, so an attribute "
                                 "is set for all of them (indices=None) or none")
            setattr(self.venv, attr_name, value)

        def env_method(self, method_name, *args, indices=None, **kw):
            """Refused: the environments are slots of one compiled batch, with no
            per-environment object to call a method of (it called the whole batch's once
            per index before 0.7.17, so env_method("reset", indices=[0]) reset them all)."""
            raise AttributeError(
                f"env_method({method_name!r}): sb3_vec_env steps one compiled batch and has no "
                "per-environment objects; use the VecEnv's own reset, seed and set_options, "
                "or DummyVecEnv over gym.make(...) for per-environment methods")

        def env_is_wrapped(self, wrapper_class, indices=None):
            return [False for _ in self._get_indices(indices)]

    return SB3VecEnv()
