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

from ..checks import is_whole
from ..sim.events import FAILURES, FIELD_END, OUTCOMES, RUNNING
from . import reward
from .batch import EnvBatch, check_num_envs
from .config import TaskConfig, TaskError
from .env import frame
from .episodes import reset_options
from .render import Renderer

DEFAULT_MAX_EPISODE_STEPS = 600
#: SAME_STEP keys beside SyncVectorEnv's layout: the ended slots' reasons at the top level
#: (SyncVectorEnv has them in ``final_info`` only; kept for the clients that read them there),
#: and their new episodes' reset infos once more with this prefix, which
#: :mod:`aerostat_gym.envs.sb3` reads
SB3_REASONS = ("termination", "failure", "truncation")
SB3_RESET_PREFIX = "reset_"


class TetheredAerostatVectorEnv(VectorEnv):
    """``num_envs`` copies of :class:`TetheredAerostatEnv` (same arguments, see its docstring)
    stepped together; ``max_episode_steps`` truncates each episode (600 by default);
    ``threads`` sets the threads of the batched step (1 to ``NUMBA_NUM_THREADS``, default all:
    on a machine shared with other busy jobs, ``threads=1`` is the safe choice).

    With ``autoreset_mode=AutoresetMode.DISABLED`` an ended environment waits for
    ``reset(options={"reset_mask": mask})``: until then it is not stepped, its observation
    stays the final one and it reports reward 0, ``terminated`` and ``truncated`` False (its
    end is reported once, on the step where it happened).

    The infos are those of Gymnasium's ``SyncVectorEnv`` over the single environment (same
    keys, ``_key`` masks and values): the stepped slots' step infos; in ``NEXT_STEP`` the
    reset info of a slot that starts its next episode in this step; in ``SAME_STEP`` an ended
    slot's step info in ``final_info`` (with ``final_obs``) and its new episode's reset info
    in its place, plus, for the SB3 adapter, its ``termination`` / ``failure`` /
    ``truncation`` at the top level and its reset info again prefixed ``reset_``.
    ``step()`` before ``reset()`` raises ``gymnasium.error.ResetNeeded``, and any call but
    ``close()`` after ``close()`` raises ``gymnasium.error.ClosedEnvironmentError``."""

    metadata = {"render_modes": ["rgb_array"], "autoreset_mode": AutoresetMode.NEXT_STEP}
    #: every slot has an episode and the env is open, so step() may go on: set by reset(),
    #: cleared by close() (a class default: also for instances made before it)
    _ready = False

    def __init__(self, num_envs: int = 1, max_episode_steps: int | None = None,
                 autoreset_mode: AutoresetMode | str = AutoresetMode.NEXT_STEP,
                 render_mode: str | None = None, threads: int | None = None, **kwargs):
        check_num_envs(num_envs)
        self.autoreset_mode = AutoresetMode(autoreset_mode)
        if render_mode not in (None, "rgb_array"):
            raise ValueError(f"unknown render_mode {render_mode!r}; the vector env renders "
                             "'rgb_array' (a frame per environment)")
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
        self._renderers = {}  # per environment, made at its first frame (see render)

    # --- Gymnasium VectorEnv API -----------------------------------------------------------

    def reset(self, *, seed=None, options=None):
        self.batch.check_open("reset()")
        opts = reset_options(options)
        mask = _reset_mask(opts.pop("reset_mask", None), self.num_envs)
        seeds = _seeds(seed, self.num_envs)
        infos = {}
        for i in np.flatnonzero(mask):
            if seeds[i] is not None or self._rngs[i] is None:
                self._rngs[i] = seeding.np_random(seeds[i])[0]
            infos = self._add_info(infos, self._reset(i, _options_for(opts, i, self.num_envs)), i)
            self._pending[i] = False
        self._ready = self.batch.started
        return self.batch.obs.copy(), infos

    def step(self, actions):
        b = self.batch
        if not self._ready:  # one flag per step; the reason is worked out only when it fails
            b.check_started("step()")
        clipped = b.set_actions(actions)
        pending = self._pending.copy()
        idle = bool(pending.any())  # NEXT_STEP resets these slots now, DISABLED holds them
        b.step(~pending)
        self._steps[~pending] += 1
        rewards = np.where(pending, 0.0, b.terms.sum(axis=1))
        code = b.code
        terminated = (code != RUNNING) & (code != FIELD_END) & ~pending
        truncated = ((code == FIELD_END) | (self._steps >= self.max_episode_steps)) \
            & ~pending & ~terminated
        info = self._step_info(clipped, pending, terminated, truncated)
        done = terminated | truncated
        for i in np.flatnonzero(~pending):
            self._noise(i)
        if self.task.reward_fn is not None:
            self._custom_rewards(rewards, pending, info)
        if idle:  # as SyncVectorEnv stacks them: a key only where some slot stepped
            info = _only_set(info)
        if self.autoreset_mode == AutoresetMode.NEXT_STEP:
            for i in np.flatnonzero(pending):  # these slots start their new episode now
                info = self._add_info(info, self._reset(i, {}), i)
            self._pending = done.copy()
        elif self.autoreset_mode == AutoresetMode.DISABLED:
            self._pending |= done
        elif done.any():
            info = self._same_step_info(info, done)
        return b.obs.copy(), rewards, terminated, truncated, info

    def render(self):
        """A tuple of rgb_array frames, one per environment, as Gymnasium's ``SyncVectorEnv``
        returns them (None without a render_mode). Before 0.7.17: environment 0's frame only."""
        self.batch.check_open("render()")
        if self.render_mode is None:
            return None
        self.batch.check_started("render()")
        return tuple(self._renderer(i).render(frame(self.batch.snapshot(i)))
                     for i in range(self.num_envs))

    def _renderer(self, i: int) -> Renderer:
        """Environment i's renderer: one each, as each environment of a SyncVectorEnv has (a
        renderer keeps its view's limits from frame to frame)."""
        if i not in self._renderers:
            self._renderers[i] = Renderer(self.batch.params, "rgb_array",
                                          fps=round(1.0 / self.task.control_step))
        return self._renderers[i]

    def close_extras(self, **kwargs):
        for renderer in self._renderers.values():
            renderer.close()
        self._renderers = {}
        self.batch.release()
        self._ready = False

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
        """The stepped slots' infos, each key as the single env's step info has it (masks:
        the stepped slots): the reward terms, action_clipped, time, peak_tension, and the
        termination (and failure) or field-end truncation reason of an ended slot (a time
        limit, the TimeLimit wrapper's, has none)."""
        b = self.batch
        stepped = ~pending
        info = {}
        for j, k in enumerate(reward.REWARD_TERMS):
            info["reward_" + k] = np.where(stepped, b.terms[:, j], 0.0)
            info["_reward_" + k] = stepped
        info["action_clipped"], info["_action_clipped"] = clipped & stepped, stepped
        info["time"], info["_time"] = np.where(stepped, b.time, 0.0), stepped
        info["peak_tension"], info["_peak_tension"] = np.where(stepped, b.peak, 0.0), stepped
        ended = terminated | (truncated & (b.code == FIELD_END))
        for i in np.flatnonzero(ended):
            code = int(b.code[i])
            _put(info, "termination" if terminated[i] else "truncation", i, OUTCOMES[code],
                 self.num_envs)
            if code in FAILURES:
                _put(info, "failure", i, OUTCOMES[code], self.num_envs)
        return info

    def _same_step_info(self, info: dict, done: np.ndarray) -> dict:
        """SAME_STEP's layout, SyncVectorEnv's: an ended slot's step info moves to
        ``final_info`` (with ``final_obs``) and its new episode's reset info takes its place;
        plus the :data:`SB3_REASONS` and :data:`SB3_RESET_PREFIX` keys."""
        final, out = {}, {}
        for key in [k for k in info if not k.startswith("_")]:
            for part, rows in ((final, info["_" + key] & done), (out, info["_" + key] & ~done)):
                if rows.any():
                    part[key], part["_" + key] = _masked(info[key], rows), rows
        out["final_obs"], out["_final_obs"] = _final_obs(self.batch.obs, done), done.copy()
        out["final_info"], out["_final_info"] = final, done.copy()
        out.update({key: final[key].copy() for k in SB3_REASONS if k in final
                    for key in (k, "_" + k)})
        for i in np.flatnonzero(done):
            started = self._reset(i, {})
            out = self._add_info(out, started, i)
            out = self._add_info(out, {SB3_RESET_PREFIX + k: v for k, v in started.items()}, i)
        return out

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
        d["_renderers"] = {}
        return d

    def __setstate__(self, d):
        d.pop("_renderer", None)  # pickled before 0.7.17: one renderer for environment 0
        self.__dict__.update(d)
        self.__dict__.setdefault("_renderers", {})


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


def _seeds(seed, n: int) -> list:
    """One seed (or None) per environment: None (all unseeded), an integer s >= 0
    (environment i gets s + i), or a list, tuple or array of n integers >= 0 or None;
    anything else is a TaskError naming it."""
    if seed is None:
        return [None] * n
    if is_whole(seed, 0):
        return [int(seed) + i for i in range(n)]
    seeds = list(seed) if isinstance(seed, (list, tuple, np.ndarray)) else None
    if seeds is None or not all(s is None or is_whole(s, 0) for s in seeds):
        raise TaskError(f"seed must be None, an integer >= 0 or a list of {n} of them (None "
                        f"for an unseeded environment), got {seed!r:.80}")
    if len(seeds) != n:
        raise TaskError(f"seed: expected a list of {n} seeds (one per environment), got "
                        f"{len(seeds)}: {seed!r:.80}")
    return [None if s is None else int(s) for s in seeds]


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


def _masked(values: np.ndarray, rows: np.ndarray) -> np.ndarray:
    """``values`` on ``rows``, the empty value elsewhere (0 / False, None for objects), as
    Gymnasium's info stacking leaves the slots that lack a key."""
    out = np.full_like(values, None) if values.dtype == object else np.zeros_like(values)
    out[rows] = values[rows]
    return out


def _only_set(info: dict) -> dict:
    """``info`` without the keys that no slot has (all-False mask)."""
    names = [k for k in info if not k.startswith("_") and info["_" + k].any()]
    return {key: info[key] for k in names for key in (k, "_" + k)}


def make_vec(num_envs: int = 1, **kwargs) -> TetheredAerostatVectorEnv:
    """The vector entry point registered for ``TetheredAerostat-v0``."""
    return TetheredAerostatVectorEnv(num_envs=num_envs, **kwargs)
