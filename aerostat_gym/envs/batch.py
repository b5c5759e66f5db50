"""The simulator behind the environments: N episodes held in flat arrays and stepped by one
compiled call. It owns time, the episode starts and the turbulence bank; the Gymnasium classes
(:mod:`aerostat_gym.envs.env`, :mod:`aerostat_gym.envs.vector`) only adapt it to their API.
"""

from __future__ import annotations

import math
import warnings

import numba
import numpy as np
from gymnasium.error import ClosedEnvironmentError, ResetNeeded

from ..analysis.trim import TrimError
from ..checks import is_whole
from ..params import Params
from ..physics.integrators import scheme
from ..physics.outputs import winch_tension
from ..physics.packing import P_SIZE
from ..physics.state import StateLayout, work_size
from ..physics.wind import W_SIZE, mean_wind, set_advection
from ..sim import Model
from ..sim.events import RUNNING, ground_height
from . import kernel as K
from . import reward, spaces
from .config import TaskConfig, TaskError
from .episodes import (
    Episode,
    TrimTable,
    bank_decorrelation,
    check_weathercock_draws,
    field_length_needed,
    sample_episode,
    unit_bank,
)

NO_BANK = np.zeros((1, 1, 0, 3))


def check_threads(threads: int | None) -> int:
    """Threads of the batched step: an integer from 1 to numba's NUMBA_NUM_THREADS (default:
    all of them); anything else is a ValueError naming the value."""
    top = numba.config.NUMBA_NUM_THREADS
    if threads is None:
        return top
    if not is_whole(threads, 1, top):
        raise ValueError(f"threads must be an integer from 1 to {top} (NUMBA_NUM_THREADS), got "
                         f"{threads!r}")
    return int(threads)


class ActionError(ValueError):
    """A non-finite, non-numeric or wrongly shaped action (the message names the value)."""


def _describe(actions) -> str:
    text = repr(actions)
    return text if len(text) <= 60 else text[:57] + "..."


def coerce_actions(actions, n: int) -> np.ndarray:
    """The actions of n environments as a float64 array of shape (n,).

    Accepted: what Gymnasium users pass, a real number (n = 1), or a list, tuple or array of
    real numbers of shape (n,) or (n, 1) (also (1,) and (1, 1) for n = 1). Refused with
    :class:`ActionError` naming what was given: strings, None, booleans, complex numbers,
    objects, and any other shape (e.g. (2, 2) or (1, 4) for n = 4).
    """
    if isinstance(actions, (bool, np.bool_)) or actions is None or isinstance(actions, str):
        raise ActionError(f"action must be a real number or an array of them, got "
                          f"{_describe(actions)}")
    if isinstance(actions, (float, int)):
        a = np.array([float(actions)])
    else:
        try:
            a = np.asarray(actions)
        except (TypeError, ValueError):
            raise ActionError(f"action must be an array of real numbers, got "
                              f"{_describe(actions)}") from None
        if a.dtype.kind not in "fiu":
            raise ActionError(f"action must hold real numbers (float or int), got dtype "
                              f"{a.dtype} from {_describe(actions)}")
    shapes = ((n,), (n, 1)) + (((), (1,), (1, 1)) if n == 1 else ())
    if a.shape not in shapes:
        raise ActionError(f"expected {n} action(s) of shape {(n,)} or {(n, 1)}, got shape "
                          f"{a.shape} from {_describe(actions)}")
    return a.astype(float).reshape(n)


#: Most environments one batch holds: each carries its own state, work, observation and reward
#: arrays and a share of the threads, and 65,536 environments already fill a many-core machine
#: (a mistyped count, 10**7, allocated 12.7 GB for minutes before failing inside numpy).
MAX_ENVS = 65_536


def check_num_envs(num_envs) -> int:
    """``num_envs`` as an int in [1, MAX_ENVS], or a ValueError naming it."""
    if not is_whole(num_envs) or num_envs > MAX_ENVS:
        raise ValueError(f"num_envs must be an integer in [1, {MAX_ENVS}], got {num_envs!r}")
    return int(num_envs)


class EnvBatch:
    """N environments of one task in flat arrays (see the module docstring).

    Parameters
    ----------
    task : TaskConfig
        The validated environment arguments.
    num_envs : int
        Number of environments.
    threads : int, optional
        Threads of the batched step (default: NUMBA_NUM_THREADS).

    Notes
    -----
    The turbulence bank does not depend on the episode length: its fields are periodic and
    read modulo their length, so every episode length is served by the same bank.
    """

    def __init__(self, task: TaskConfig, num_envs: int, threads: int | None = None):
        self.task = task
        self.num_envs = N = check_num_envs(num_envs)
        self.threads = check_threads(threads)
        params = task.params_resolved
        self.params = params
        self.layout = StateLayout(params.tether.n_elements)
        S = self.layout.size
        self.full_size = S if task.observation == "full" else 0
        self.obs_dim = spaces.N_OBS + (1 + S if self.full_size else 0)
        self.obs_low, self.obs_high = spaces.bounds(self.full_size, params)
        self.trims = trim_table(task)
        self.closed = False  # set by release(): the bank is gone
        self.bank = self._bank()
        self.cfg = self._config(params)
        # per-slot arrays, one row per environment
        self.state = np.zeros((N, S))  # simulator state (StateLayout order)
        self.state_prev = np.zeros((N, S))  # state at the start of the step (restored on failure)
        self.trim_state = np.zeros((N, S))  # the episode's trim
        self.trim_tension = np.zeros(N)  # winch tension at the trim [N]
        self.time = np.zeros(N)  # episode time [s]
        self.action = np.zeros(N)  # action of the step in [-1, 1]
        self.action_prev = np.zeros(N)
        self.braked = np.zeros(N, dtype=np.bool_)  # the brake holds the drum
        self.quiet = np.zeros(N)  # time the set-point has stood still (brake dwell clock) [s]
        self._clipped = np.zeros(N, dtype=np.bool_)
        self.packed = np.zeros((N, P_SIZE))  # packed parameters (randomised per episode)
        self.wind = np.zeros((N, W_SIZE))  # packed wind vector (mean, gust, field grid)
        self.field_index = np.zeros(N, dtype=np.int64)  # bank field read by the slot
        self.work = np.zeros((N, work_size(params.tether.n_elements)))
        self.obs = np.zeros((N, self.obs_dim), dtype=np.float32)
        self.terms = np.zeros((N, len(reward.REWARD_TERMS)))  # default reward terms
        self.code = np.zeros(N, dtype=np.int64)  # outcome code of the last step
        self.peak = np.zeros(N)  # largest element tension over the last step [N]
        self.episodes: list = [None] * N
        self.scale = spaces.scales()
        self.low64 = self.obs_low[:spaces.N_OBS].astype(float)
        self.high64 = self.obs_high[:spaces.N_OBS].astype(float)

    def _bank(self) -> np.ndarray:
        turb = self.task.resolved["turbulence"]
        self._bank_key = None  # what the bank is made from (see world())
        self._decorrelation = np.zeros((0, 3))  # 1 - rho of its adjacent rows
        if turb.is_off:
            return NO_BANK
        u_max = self.trims.speeds[-1] * _advection_factor(self.params, turb)
        need = field_length_needed(turb, u_max)
        # unit-variance fields, scaled per episode to its mean wind (episodes._intensity)
        bank = unit_bank(turb, self.task.wind_bank_size, self.task.wind_bank_seed, need)
        self._bank_key = (repr(turb.unit()), self.task.wind_bank_size, self.task.wind_bank_seed,
                          bank.shape)
        self._decorrelation = bank_decorrelation(bank)
        return bank

    def release(self) -> None:
        """Drop this batch's reference to the turbulence bank (freed with its last user): the
        batch is closed, and its environments refuse every call but close (see
        :meth:`check_open`)."""
        self.bank = NO_BANK
        self.closed = True

    def check_open(self, call: str) -> None:
        """Refuse ``call`` on a closed batch: without its turbulence bank it would run in calm
        air while its infos still report the turbulence."""
        if self.closed:
            raise ClosedEnvironmentError(
                f"{call} on a closed environment: close() released its turbulence fields; "
                "make a new environment to go on")

    def check_started(self, call: str) -> None:
        """Refuse ``call`` (step, render) on an open batch with a slot that has no episode: its
        all-zero state would only read as a numerical failure."""
        self.check_open(call)
        idle = [i for i, ep in enumerate(self.episodes) if ep is None]
        if idle:
            which = "" if self.num_envs == 1 else f" (environment(s) {idle[:4]} never reset)"
            raise ResetNeeded(f"{call} before reset(){which}: call reset() to start an "
                              "episode first")

    @property
    def started(self) -> bool:
        """Whether the batch is open and every slot has an episode (a step may run)."""
        return not self.closed and all(ep is not None for ep in self.episodes)

    def __getstate__(self):  # the trims and the bank are rebuilt (or found in the cache)
        d = dict(self.__dict__)
        d["trims"] = d["bank"] = None
        return d

    def __setstate__(self, d):
        self.__dict__.update(d)
        self.__dict__.setdefault("closed", False)  # pickled before the flag existed
        self.__dict__.setdefault("_bank_key", None)  # set by _bank() on an open batch
        self.trims = TrimTable(self.params, *self.task.resolved["wind_speed"])
        # found in the cache while another holder lives; a closed batch stays closed
        self.bank = NO_BANK if self.closed else self._bank()

    def _config(self, params) -> np.ndarray:
        t, w = self.task, params.winch
        cfg = np.zeros(K.C_SIZE)
        sim = params.simulation
        cfg[:K.C_DT] = scheme(t.integrator, sim.rk4_safety, sim.semi_implicit_dt)
        cfg[K.C_DT] = t.control_step
        cfg[K.C_GROUND] = ground_height(params)
        cfg[K.C_BRAKE_SPEED] = w.brake_speed
        cfg[K.C_HOLD_SPEED] = w.brake_hold_speed
        cfg[K.C_BRAKE_DWELL] = w.brake_dwell
        cfg[K.C_SWL] = w.safe_working_load
        cfg[K.C_FULL] = 1.0 if self.full_size else 0.0
        cfg[K.C_HORIZON] = math.inf  # the periodic field serves any episode length
        cfg[K.C_FMAX] = w.max_motor_force
        cfg[K.C_WEIGHTS:] = reward.sized_weights(t.resolved["weights"], params.tether.length)
        cfg[K.C_LENGTH_BAND] = (reward.LENGTH_BAND_FRACTION * params.tether.length
                                / spaces.CHANNELS[spaces.OBS_DLENGTH].scale)
        return cfg

    # --- episodes --------------------------------------------------------------------------

    def reset_one(self, i: int, rng: np.random.Generator, options: dict | None = None) -> dict:
        """Start a new episode in slot i; fills obs[i] and returns the episode info."""
        ep = sample_episode(self.task, self.trims, self.bank.shape, rng, options,
                            self._decorrelation)
        self.state[i] = ep.x0
        self.trim_state[i] = ep.x_trim
        self.trim_tension[i] = ep.tension_trim
        self.packed[i] = ep.p
        self.wind[i] = ep.wp
        self.field_index[i] = ep.field_index
        self.time[i] = 0.0
        self.action[i] = self.action_prev[i] = 0.0
        self.braked[i] = False
        self.quiet[i] = 0.0
        self.code[i] = RUNNING
        self.peak[i] = 0.0
        self.episodes[i] = ep
        self.observe(i)
        return dict(ep.info)

    def observe(self, i: int) -> None:
        """Recompute obs[i] (no noise) and the work array from slot i's state; a state whose
        outputs are not finite (refused parameters should make this impossible) is an error."""
        T_w = K.observe(self.state[i], self.time[i], self.packed[i], self.wind[i],
                        self.bank[self.field_index[i]], self.work[i], self.cfg,
                        self.trim_state[i], self.trim_tension[i], self.scale, self.low64,
                        self.high64, self.obs[i])
        if not math.isfinite(T_w):
            raise FloatingPointError(f"environment {i}: the state gives non-finite outputs "
                                     f"(winch tension {T_w!r})")

    def winch_tensions(self) -> np.ndarray:
        """Winch tension [N] of every slot's state, noise-free and unclipped (from the work
        arrays, which every step, reset and restore fills for the slot's current state)."""
        return np.array([winch_tension(self.state[i], self.packed[i], self.work[i])
                         for i in range(self.num_envs)])

    #: Per-slot arrays that make up the simulator state of one environment.
    SLOT_ARRAYS = ("state", "trim_state", "trim_tension", "time", "action", "action_prev",
                   "braked", "quiet", "packed", "wind", "field_index", "obs", "terms", "code",
                   "peak")

    def get_slot(self, i: int) -> dict:
        """A copy of everything that determines slot i's future (see :meth:`set_slot`)."""
        out = {name: np.copy(getattr(self, name)[i]) for name in self.SLOT_ARRAYS}
        out["episode"] = self.episodes[i]
        out["world"] = self.world()  # the batch-wide half of the slot's future
        return out

    def set_slot(self, i: int, saved: dict) -> None:
        """Restore slot i from :meth:`get_slot`'s output: stepping on from it reproduces the
        original run bit for bit (the work arrays are recomputed by every step)."""
        self.check_open("set_state()")
        missing = sorted(set(self.SLOT_ARRAYS) - set(saved))
        if missing:
            raise ValueError(f"simulator state lacks {missing}")
        if np.shape(saved["state"]) != self.state[i].shape:
            raise ValueError(f"simulator state has shape {np.shape(saved['state'])}, this "
                             f"environment's is {self.state[i].shape}")
        if not isinstance(saved["episode"], Episode):
            raise ValueError(f"simulator state's episode is a {type(saved['episode']).__name__}, "
                             "not the Episode from get_state() (a snapshot keeps its episode "
                             "through pickle, not through JSON or YAML)")
        self._check_same_world(saved.get("world"))
        for name in self.SLOT_ARRAYS:
            getattr(self, name)[i] = saved[name]
        self.episodes[i] = saved["episode"]
        obs = self.obs[i].copy()
        self.observe(i)  # the work array: the step reads the winch tension of its start state
        self.obs[i] = obs

    def world(self) -> dict:
        """What the batch, not the slot, contributes to a slot's future, by name: the
        turbulence fields the slot reads, the control step, the ground, winch and reward
        settings of the configuration vector, the observation's layout, bounds and noise.
        Equal arguments resolve to an equal world (``params=None`` and the baseline loaded,
        ``(8, 8)`` and ``8``); the integration scheme is not part of it (a snapshot may be
        re-run on a finer step or with the other integrator) and neither is a ``reward_fn``.
        What the snapshot carries itself (the packed parameters of its episode: hull, tether,
        winch dynamics) runs on as saved whatever this batch's parameters are."""
        c = self.cfg
        return {
            "turbulence fields": self._bank_key,
            "control_step": float(c[K.C_DT]),
            "ground height (hull diameter)": float(c[K.C_GROUND]),
            "winch brake and limits": c[[K.C_BRAKE_SPEED, K.C_HOLD_SPEED, K.C_BRAKE_DWELL,
                                         K.C_SWL, K.C_FMAX]].tolist(),
            "reward weights and length band": c[K.C_LENGTH_BAND:].tolist(),
            "observation bounds": (self.obs_low.tolist(), self.obs_high.tolist()),
            "obs_noise": float(self.task.obs_noise),
        }

    def _check_same_world(self, world: dict | None) -> None:
        """A snapshot runs on as saved only in a batch of the same world (:meth:`world`):
        another one (another control step, turbulence, ground height, winch limits, reward or
        observation) is refused, naming what differs. A snapshot without its world (taken before aerostat-gym 0.7.16) is taken on
        trust."""
        if world is None:
            return
        if not isinstance(world, dict):
            raise ValueError("simulator state's world is not a dict from get_state()")
        mine = self.world()
        differ = [k for k in mine if _as_lists(world.get(k)) != _as_lists(mine[k])]
        if differ:
            raise ValueError(
                f"the snapshot comes from an environment of another world ({', '.join(differ)}):"
                " restored here it would not go on as saved; restore it into an environment "
                "made with the same arguments")

    def set_actions(self, actions) -> np.ndarray:
        """Validate and store actions (see :func:`coerce_actions`): NaN/inf is an ActionError,
        out-of-range values are clipped to [-1, 1]. Returns the per-env clipped flags (a buffer
        reused by the next call)."""
        a = coerce_actions(actions, self.num_envs)
        scalar = self.num_envs == 1  # scalar arithmetic: each numpy call costs ~1 us per step
        if not (math.isfinite(a[0]) if scalar else np.all(np.isfinite(a))):
            idx = np.flatnonzero(~np.isfinite(a))
            raise ActionError(f"action must be finite, got {a[idx][:4].tolist()} "
                              f"(environment(s) {idx[:4].tolist()})")
        if scalar:
            v = float(a[0])
            self._clipped[0] = abs(v) > 1.0
            self.action[0] = min(max(v, -1.0), 1.0)
        else:
            np.greater(np.abs(a), 1.0, out=self._clipped)
            np.clip(a, -1.0, 1.0, out=self.action)
        return self._clipped

    def _arrays(self) -> tuple:
        return (self.state, self.state_prev, self.time, self.action, self.action_prev,
                self.braked, self.quiet, self.packed, self.wind, self.bank, self.field_index, self.work,
                self.cfg, self.trim_state, self.trim_tension, self.scale, self.low64, self.high64,
                self.obs, self.terms, self.code, self.peak)

    def step(self, active: np.ndarray | None = None) -> None:
        """Advance every active environment one control step with the stored actions."""
        if active is None and self.num_envs == 1:
            K.step_serial(*self._arrays())
            return
        if active is None:
            active = np.ones(self.num_envs, dtype=np.bool_)
        if numba.get_num_threads() != self.threads:
            numba.set_num_threads(self.threads)
        K.step_parallel(active, *self._arrays())

    def add_noise(self, i: int, rng: np.random.Generator) -> None:
        """Gaussian sensor noise of std ``obs_noise`` (in scaled units) on the standard channels."""
        sigma = self.task.obs_noise
        if sigma > 0.0:
            o = self.obs[i, :spaces.N_OBS]
            o += rng.normal(0.0, sigma, o.shape).astype(np.float32)
            np.clip(o, self.obs_low[:spaces.N_OBS], self.obs_high[:spaces.N_OBS], out=o)

    def snapshot(self, i: int) -> dict:
        """Physical quantities of environment i for rendering and diagnostics."""
        ep = self.episodes[i]
        x = self.state[i].copy()
        model = Model(ep.params, (self.wind[i], self.bank[self.field_index[i]]))
        lay = self.layout
        return {"time": float(self.time[i]), "state": x, "nodes": model.node_positions(x),
                "cm_pos": x[lay.cm_pos], "euler": x[lay.euler],
                "trim_cm": self.trim_state[i][lay.cm_pos],
                "tension": model.end_tensions(x, float(self.time[i]))[1],
                "length": float(x[lay.winch_length]), "reel_speed": float(x[lay.winch_speed]),
                "wind_speed": ep.wind_speed, "params": ep.params}


def held_wind_top(params: Params, lo: float, hi: float) -> float:
    """The highest wind of the trim table of [lo, hi] (its 0.1 m/s grid points and its ends)
    whose trim the configured tether holds
    (largest tension below ``tether.strength``, :func:`~aerostat_gym.analysis.trim.
    largest_trim_tension`; it grows with the wind), ``hi`` where it holds them all and ``lo``
    where it holds none (:func:`trim_table` then names the tension)."""
    trims = TrimTable(params, lo, hi)
    held = trims.largest_tensions < params.tether.strength
    if held.all() or not held[0]:
        return hi if held.all() else lo
    return float(trims.speeds[np.argmin(held) - 1])


def trim_table(task: TaskConfig) -> TrimTable:
    """The task's trim table, refused (TaskError) where the configured tether cannot hold the
    trim anywhere in the wind range, with a warning where the winch motor cannot (it then holds
    on its brake: reel-in commands cannot be obeyed at those winds); with ``weathercock=True``,
    refused where nearly no randomised aerostat weathervanes."""
    params = task.params_resolved
    lo, hi = task.resolved["wind_speed"]
    try:
        trims = TrimTable(params, lo, hi)
    except TrimError as exc:
        raise TaskError(f"wind_speed {(lo, hi)}: no trim for these parameters: {exc}") from None
    k = int(np.argmax(trims.largest_tensions))
    T, U = float(trims.largest_tensions[k]), float(trims.speeds[k])
    strength = params.tether.strength
    if T >= strength:
        raise TaskError(f"wind_speed up to {hi} m/s: the trim at {U} m/s loads the tether with "
                        f"{T:.0f} N, above tether.strength = {strength:.0f} N")
    fmax = params.winch.max_motor_force
    if T > fmax:
        first = float(trims.speeds[np.argmax(trims.tensions > fmax)])
        warnings.warn(f"wind_speed up to {hi} m/s: from {first} m/s the trim tension exceeds "
                      f"winch.max_motor_force = {fmax:.0f} N; the winch holds on its brake "
                      "against reel-in commands there", stacklevel=3)
    check_weathercock_draws(task, trims)
    return trims


def _advection_factor(params, turb) -> float:
    """U_a / U_ref for the configured mean profile (1 for the paper's uniform wind)."""
    return set_advection(mean_wind(params.wind, 1.0), turb.reference_height, 0.0)


def _as_lists(value):
    """``value`` with every tuple a list, recursively: a snapshot's ``world`` entry compares
    equal after a trip through JSON or YAML (which write tuples as lists; the snapshot as a
    whole goes through pickle, its episode has no JSON form)."""
    if isinstance(value, (tuple, list)):
        return [_as_lists(v) for v in value]
    return value
