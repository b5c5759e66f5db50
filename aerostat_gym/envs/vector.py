"""Native batched environments: N episodes stepped by one compiled call, parallel over
environments (numba ``prange``; ``NUMBA_NUM_THREADS`` sets the threads).

- :class:`TetheredAerostatVectorEnv`: a ``gymnasium.vector.VectorEnv``, what
  ``gym.make_vec("TetheredAerostat-v0", num_envs=N, vectorization_mode="vector_entry_point")``
  returns; Gymnasium's autoreset semantics (``NEXT_STEP`` by default, ``SAME_STEP`` or
  ``DISABLED`` on request: ``autoreset_mode=...``).
- :func:`aerostat_gym.envs.sb3.sb3_vec_env`: the same batch as a Stable-Baselines3 ``VecEnv``
  (same-step reset with ``info["terminal_observation"]``), so training needs no subprocesses.

Environment i is seeded with ``seed + i`` and then equals a single ``TetheredAerostat-v0``
reset with that seed, step for step.
"""

from __future__ import annotations

import gymnasium as gym
import numpy as np
from gymnasium.utils import seeding
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from ..checks import is_number, is_whole
from ..sim.events import FAILURES, FIELD_END, OUTCOMES, RUNNING
from . import reward
from .batch import EnvBatch
from .config import TaskConfig
from .env import frame
from .episodes import reset_options
from .render import Renderer

DEFAULT_MAX_EPISODE_STEPS = 600


class TetheredAerostatVectorEnv(VectorEnv):
    """``num_envs`` copies of :class:`TetheredAerostatEnv` (same arguments, see its docstring)
    stepped together; ``max_episode_steps`` truncates each episode (600 by default);
    ``threads`` sets the threads of the batched step (1 to ``NUMBA_NUM_THREADS``, default all:
    on a machine shared with other busy jobs, ``threads=1`` is the safe choice).

    With ``autoreset_mode=AutoresetMode.DISABLED`` an ended environment waits for
    ``reset(options={"reset_mask": mask})``: until then it is not stepped, its observation
    stays the final one and it reports reward 0, ``terminated`` and ``truncated`` False (its
    end is reported once, on the step where it happened)."""

    metadata = {"render_modes": ["rgb_array"], "autoreset_mode": AutoresetMode.NEXT_STEP}

    def __init__(self, num_envs: int = 1, max_episode_steps: int | None = None,
                 autoreset_mode: AutoresetMode | str = AutoresetMode.NEXT_STEP,
                 render_mode: str | None = None, threads: int | None = None, **kwargs):
        if not is_whole(num_envs):
            raise ValueError(f"num_envs must be an integer >= 1, got {num_envs!r}")
        self.autoreset_mode = AutoresetMode(autoreset_mode)
        if render_mode not in (None, "rgb_array"):
            raise ValueError(f"unknown render_mode {render_mode!r}; the vector env renders "
                             "'rgb_array' (environment 0)")
        self.render_mode = render_mode
        self.metadata = {**self.metadata, "autoreset_mode": self.autoreset_mode}
        self.task = TaskConfig.from_kwargs(**kwargs)
        if max_episode_steps is None:
            max_episode_steps = DEFAULT_MAX_EPISODE_STEPS
        if not is_whole(max_episode_steps):
            raise ValueError(f"max_episode_steps must be an integer >= 1, got {max_episode_steps!r}")
        self.max_episode_steps = int(max_episode_steps)
        self.num_envs = int(num_envs)
        self.batch = EnvBatch(self.task, num_envs, threads)
        b = self.batch
        self.single_action_space = gym.spaces.Box(-1.0, 1.0, (1,), np.float32)
        self.single_observation_space = gym.spaces.Box(b.obs_low, b.obs_high, dtype=np.float32)
        self.action_space = batch_space(self.single_action_space, num_envs)
        self.observation_space = batch_space(self.single_observation_space, num_envs)
        self._rngs = [seeding.np_random(None)[0] for _ in range(num_envs)]
        self._steps = np.zeros(num_envs, dtype=np.int64)
        # ended, not stepped: NEXT_STEP resets these at the next step, DISABLED waits for reset()
        self._pending = np.zeros(num_envs, dtype=np.bool_)
        self._renderer = None

    # --- Gymnasium VectorEnv API -----------------------------------------------------------

    def reset(self, *, seed=None, options=None):
        opts = reset_options(options)
        mask = _reset_mask(opts.pop("reset_mask", None), self.num_envs)
        seeds = _seeds(seed, self.num_envs)
        infos = []
        for i in np.flatnonzero(mask):
            if seeds[i] is not None or self._rngs[i] is None:
                self._rngs[i] = seeding.np_random(seeds[i])[0]
            infos.append((i, self._reset(i, _options_for(opts, i, self.num_envs))))
            self._pending[i] = False
        return self.batch.obs.copy(), _stack_infos(infos, self.num_envs)

    def step(self, actions):
        b = self.batch
        clipped = b.set_actions(actions)
        pending = self._pending.copy()
        b.step(~pending)
        self._steps[~pending] += 1
        rewards = np.where(pending, 0.0, b.terms.sum(axis=1))
        code = b.code
        terminated = (code != RUNNING) & (code != FIELD_END) & ~pending
        truncated = ((code == FIELD_END) | (self._steps >= self.max_episode_steps)) \
            & ~pending & ~terminated
        info = self._step_info(clipped, pending, terminated, truncated)
        done = terminated | truncated
        if pending.any() and self.autoreset_mode == AutoresetMode.NEXT_STEP:
            # these slots start their new episode now
            resets = [(i, self._reset(i, {})) for i in np.flatnonzero(pending)]
            info.update(_stack_infos(resets, self.num_envs, prefix="reset_"))
        for i in np.flatnonzero(~pending):
            self._noise(i)
        if self.task.reward_fn is not None:
            self._custom_rewards(rewards, pending, info)
        if self.autoreset_mode == AutoresetMode.NEXT_STEP:
            self._pending = done.copy()
        elif self.autoreset_mode == AutoresetMode.DISABLED:
            self._pending |= done
        elif done.any():
            info["final_obs"] = _final_obs(b.obs, done)
            info["_final_obs"] = done.copy()
            resets = [(i, self._reset(i, {})) for i in np.flatnonzero(done)]
            info.update(_stack_infos(resets, self.num_envs, prefix="reset_"))
        return b.obs.copy(), rewards, terminated, truncated, info

    def render(self):
        """An rgb_array frame of environment 0 (None without a render_mode)."""
        if self.render_mode is None:
            return None
        if self._renderer is None:
            self._renderer = Renderer(self.batch.params, "rgb_array",
                                      fps=round(1.0 / self.task.control_step))
        return self._renderer.render(frame(self.batch.snapshot(0)))

    def close_extras(self, **kwargs):
        if self._renderer is not None:
            self._renderer.close()
        self.batch.release()

    # --- helpers ---------------------------------------------------------------------------

    def _reset(self, i: int, options: dict) -> dict:
        info = self.batch.reset_one(i, self._rngs[i], options)
        self._noise(i)
        self._steps[i] = 0
        return info

    def _noise(self, i: int) -> None:
        if self.task.obs_noise > 0.0:
            self.batch.add_noise(i, self._rngs[i])

    def _step_info(self, clipped, pending, terminated, truncated) -> dict:
        b = self.batch
        stepped = ~pending
        info = {}
        for j, k in enumerate(reward.REWARD_TERMS):
            info["reward_" + k] = np.where(stepped, b.terms[:, j], 0.0)
            info["_reward_" + k] = stepped
        info["peak_tension"], info["_peak_tension"] = np.where(stepped, b.peak, 0.0), stepped
        info["action_clipped"], info["_action_clipped"] = clipped & stepped, stepped
        ended = terminated | truncated
        if ended.any():
            key = {True: "termination", False: "truncation"}
            for i in np.flatnonzero(ended):
                name = key[bool(terminated[i])]
                code = int(b.code[i])
                reason = OUTCOMES.get(code, "time_limit")
                _put(info, name, i, reason, self.num_envs)
                if code in FAILURES:
                    _put(info, "failure", i, reason, self.num_envs)
        return info

    def _custom_rewards(self, rewards, pending, info) -> None:
        """Replace the stepped slots' rewards by the user's reward_fn (env i's own info)."""
        b = self.batch
        for i in np.flatnonzero(~pending):
            info_i = {k: v[i] for k, v in info.items()
                      if not k.startswith("_") and info["_" + k][i]}
            rewards[i] = reward.custom_reward(self.task.reward_fn, b.obs[i].copy(),
                                              b.action[i], info_i)

    def __getstate__(self):
        d = dict(self.__dict__)
        d["_renderer"] = None
        return d


def _final_obs(obs: np.ndarray, done: np.ndarray) -> np.ndarray:
    """Gymnasium's same-step ``final_obs``: a 1-D object array holding each ended slot's
    float32 observation (None elsewhere). Built element by element: ``np.array`` of a list of
    equal-shape arrays would make a 2-D object array of scalars instead."""
    out = np.full(obs.shape[0], None, dtype=object)
    for i in np.flatnonzero(done):
        out[i] = obs[i].copy()
    return out


def _reset_mask(mask, n: int) -> np.ndarray:
    """Which environments ``reset`` resets: all without a mask; else a boolean per
    environment."""
    if mask is None:
        return np.ones(n, dtype=bool)
    arr = np.asarray(mask)
    if arr.shape != (n,) or arr.dtype != np.bool_:
        raise ValueError(f"reset_mask must be a boolean array of shape ({n},), got "
                         f"{arr.dtype} of shape {arr.shape}")
    return arr


def _seeds(seed, n):
    if seed is None:
        return [None] * n
    if isinstance(seed, (int, np.integer)):
        return [int(seed) + i for i in range(n)]
    seeds = list(seed)
    if len(seeds) != n:
        raise ValueError(f"expected {n} seeds, got {len(seeds)}")
    return seeds


def _options_for(options: dict, i: int, n: int) -> dict:
    """Reset options of environment i: a list or array of length num_envs gives one value per
    environment (e.g. ``{"wind_speed": [5, 10, 15]}``); anything else is shared."""
    return {k: (v[i] if isinstance(v, (list, tuple, np.ndarray)) and len(v) == n else v)
            for k, v in options.items()}


def _put(info, key, i, value, n):
    if key not in info:
        info[key] = np.array([None] * n, dtype=object)
        info["_" + key] = np.zeros(n, dtype=bool)
    info[key][i] = value
    info["_" + key][i] = True


def _stack_infos(pairs, n, prefix=""):
    """Gymnasium's vector info layout: per key an array over environments and a mask."""
    out = {}
    for i, d in pairs:
        for k, v in d.items():
            key = prefix + k
            if key not in out:
                numeric = is_number(v)
                out[key] = np.zeros(n) if numeric else np.array([None] * n, dtype=object)
                out["_" + key] = np.zeros(n, dtype=bool)
            out[key][i] = v
            out["_" + key][i] = True
    return out


def make_vec(num_envs: int = 1, **kwargs) -> TetheredAerostatVectorEnv:
    """The vector entry point registered for ``TetheredAerostat-v0``."""
    return TetheredAerostatVectorEnv(num_envs=num_envs, **kwargs)
